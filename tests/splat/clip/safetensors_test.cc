#include "splat/clip/safetensors.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "tests/test_util.h"

namespace splat {
namespace {

namespace fs = std::filesystem;

// A safetensors file with the given JSON header and data bytes.
void write_raw(const fs::path& file, const std::string& header, const std::string& data) {
  std::string bytes(8, '\0');
  uint64_t n = header.size();
  for (int i = 0; i < 8; ++i) bytes[i] = char((n >> (8 * i)) & 0xff);
  std::ofstream(file, std::ios::binary) << bytes << header << data;
}

// Little-endian 16-bit values as bytes.
std::string halves(std::initializer_list<uint16_t> values) {
  std::string s;
  for (uint16_t v : values) s += char(v & 0xff), s += char(v >> 8);
  return s;
}

TEST(Safetensors, RoundTripsAndRejectsTruncatedFiles) {
  const testing_util::TempDir tmp;
  const fs::path dir = tmp.path();
  std::map<std::string, Tensor> tensors;
  tensors["a"] = Tensor{{2, 3}, {1, 2, 3, 4, 5, 6}};
  tensors["b.c"] = Tensor{{1}, {-0.5f}};
  write_safetensors(dir / "t.safetensors", tensors);
  const SafetensorsFile f(dir / "t.safetensors");
  EXPECT_EQ(f.read("a").values, tensors["a"].values);
  EXPECT_EQ(f.read("b.c", {1}).values[0], -0.5f);
  EXPECT_THROW(f.read("b.c", {2}), InputError);
  EXPECT_THROW(f.read("missing"), InputError);

  const std::string bytes = read_text_file(dir / "t.safetensors");
  std::ofstream(dir / "short.safetensors", std::ios::binary) << bytes.substr(0, bytes.size() - 8);
  EXPECT_THROW(SafetensorsFile(dir / "short.safetensors"), InputError);
  std::ofstream(dir / "junk.safetensors", std::ios::binary) << "not a tensor file";
  EXPECT_THROW(SafetensorsFile(dir / "junk.safetensors"), InputError);
}

TEST(Safetensors, ConvertsHalfAndBfloat16ToFloat) {
  const testing_util::TempDir tmp;
  const fs::path file = tmp / "h.safetensors";
  write_raw(file,
            R"({"__metadata__":{"format":"pt"},)"
            R"("f16":{"dtype":"F16","shape":[3],"data_offsets":[0,6]},)"
            R"("bf16":{"dtype":"BF16","shape":[1,3],"data_offsets":[6,12]}})",
            halves({0x3C00, 0xC000, 0x3800}) + halves({0x3F80, 0xC000, 0x3F00}));
  const SafetensorsFile f(file);
  EXPECT_EQ(f.names(), (std::vector<std::string>{"bf16", "f16"}));
  EXPECT_EQ(f.read("f16").values, (std::vector<float>{1.f, -2.f, 0.5f}));
  const Tensor b = f.read("bf16", {1, 3});
  EXPECT_EQ(b.values, (std::vector<float>{1.f, -2.f, 0.5f}));
  EXPECT_EQ(b.dim(1), 3);
}

TEST(Safetensors, RejectsOtherDtypesBadOffsetsAndShapesNamingTheFile) {
  const testing_util::TempDir tmp;
  const fs::path ints = tmp / "i.safetensors";
  write_raw(ints, R"({"i":{"dtype":"I32","shape":[1],"data_offsets":[0,4]}})",
            std::string(4, '\0'));
  try {
    SafetensorsFile(ints).read("i");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("i.safetensors"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("I32"), std::string::npos);
  }
  const fs::path past = tmp / "p.safetensors";
  write_raw(past, R"({"t":{"dtype":"F32","shape":[4],"data_offsets":[0,16]}})",
            std::string(8, '\0'));
  EXPECT_THROW(SafetensorsFile{past}, InputError);
  const fs::path reversed = tmp / "r.safetensors";
  write_raw(reversed, R"({"t":{"dtype":"F32","shape":[1],"data_offsets":[4,0]}})",
            std::string(4, '\0'));
  EXPECT_THROW(SafetensorsFile{reversed}, InputError);
  const fs::path mismatch = tmp / "m.safetensors";
  write_raw(mismatch, R"({"t":{"dtype":"F32","shape":[3],"data_offsets":[0,8]}})",
            std::string(8, '\0'));
  EXPECT_THROW(SafetensorsFile(mismatch).read("t"), InputError);
  const fs::path header = tmp / "j.safetensors";
  write_raw(header, R"({"t":)", "");
  EXPECT_THROW(SafetensorsFile{header}, InputError);
  EXPECT_THROW(SafetensorsFile(tmp / "absent.safetensors"), InputError);
}

}  // namespace
}  // namespace splat
