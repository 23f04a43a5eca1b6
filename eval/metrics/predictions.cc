#include "eval/metrics/predictions.h"

#include <tbb/parallel_for.h>

#include <vector>

#include "splat/error.h"
#include "splat/id_maps.h"
#include "splat/image.h"

namespace eval {
namespace fs = std::filesystem;

ObjectMasks read_view_predictions(const fs::path& folder, const std::string& view_name) {
  const std::string stem = fs::path(view_name).stem().string();
  const fs::path label_map = folder / (stem + ".png");
  if (fs::is_regular_file(label_map)) {
    const splat::IdMap ids = splat::read_id_map(label_map);
    return masks_from_label_map(std::vector<int32_t>(ids.ids.begin(), ids.ids.end()), ids.width,
                                ids.height);
  }
  const fs::path masks = folder / stem;
  if (!fs::is_directory(masks))
    throw splat::InputError(folder, "no prediction for view " + view_name + " (neither " + stem +
                                        ".png nor " + stem + "/<id>.png)");
  std::vector<std::pair<int32_t, fs::path>> files;
  for (const auto& f : fs::directory_iterator(masks)) {
    if (f.path().extension() != ".png") continue;
    const std::string id = f.path().stem().string();
    if (id.empty() || id.find_first_not_of("0123456789") != std::string::npos) continue;
    files.push_back({std::stoi(id), f.path()});
  }
  std::vector<Mask> decoded(files.size());
  tbb::parallel_for(size_t(0), files.size(),
                    [&](size_t i) { decoded[i] = read_mask(files[i].second); });
  ObjectMasks out;
  for (size_t i = 0; i < files.size(); ++i) out[files[i].first] = std::move(decoded[i]);
  return out;
}

}  // namespace eval
