// CLIP weights in safetensors files (splat/clip/safetensors.h): the header,
// then every tensor it names.
#include "splat/clip/safetensors.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto file = fuzz::work_dir() / "model.safetensors";
  fuzz::write_file(file, data, size);
  fuzz::expect_only_input_errors([&] {
    const splat::SafetensorsFile f(file);
    for (const std::string& name : f.names())
      fuzz::expect_only_input_errors([&] { f.read(name); });
  });
  return 0;
}
