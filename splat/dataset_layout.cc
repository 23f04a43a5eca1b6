#include "splat/dataset_layout.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>

#include "splat/error.h"

namespace splat {
namespace fs = std::filesystem;

DatasetLayout detect_dataset_layout(const fs::path& scene) {
  auto has = [&](const char* name) { return fs::exists(scene / name); };
  if (has("images_train") || has("test_mask")) return DatasetLayout::kLerfMask;
  if (has("segmentations"))
    return has("object_mask_deva") ? DatasetLayout::kOvsPrepared : DatasetLayout::kOvsOriginal;
  return DatasetLayout::kPhotos;
}

std::string layout_name(DatasetLayout layout) {
  switch (layout) {
    case DatasetLayout::kLerfMask:
      return "lerf-mask";
    case DatasetLayout::kOvsOriginal:
      return "3dovs";
    case DatasetLayout::kOvsPrepared:
      return "3dovs-prepared";
    case DatasetLayout::kPhotos:
      break;
  }
  return "photos";
}

std::string layout_description(DatasetLayout layout) {
  switch (layout) {
    case DatasetLayout::kLerfMask:
      return "LERF-Mask layout: training views in images_train/, ground truth in test_mask/, "
             "ID maps in object_mask/ (or sam2/)";
    case DatasetLayout::kOvsOriginal:
      return "3DOVS as released: LLFF poses, every view trains, segmentations/ scored";
    case DatasetLayout::kOvsPrepared:
      return "3DOVS as the 3DGS papers prepare it: sparse/0/, ID maps in object_mask_deva/, "
             "the segmented views held out as the fixed test frames";
    case DatasetLayout::kPhotos:
      break;
  }
  return "photos: ID maps in sam2/, every 8th view held out";
}

std::vector<std::string> id_map_folder_candidates(DatasetLayout layout) {
  switch (layout) {
    case DatasetLayout::kLerfMask:
      return {"object_mask", "sam2", "object_mask_deva"};
    case DatasetLayout::kOvsPrepared:
      return {"object_mask_deva", "sam2", "object_mask"};
    case DatasetLayout::kOvsOriginal:
    case DatasetLayout::kPhotos:
      break;
  }
  return {"sam2", "object_mask", "object_mask_deva"};
}

std::vector<std::string> sorted_image_names(const fs::path& scene) {
  std::vector<std::string> names;
  for (const auto& f : fs::directory_iterator(scene / "images"))
    if (f.is_regular_file()) names.push_back(f.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::vector<SegmentedView> segmented_views(const fs::path& scene) {
  const std::vector<std::string> images = sorted_image_names(scene);
  std::vector<SegmentedView> views;
  for (const auto& d : fs::directory_iterator(scene / "segmentations")) {
    if (!d.is_directory()) continue;
    const std::string name = d.path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos)
      throw InputError(d.path(), "segmentation folders must be image indices");
    const size_t index = std::stoul(name);
    if (index >= images.size()) throw InputError(d.path(), "no image with this index in images/");
    views.push_back({index, images[index], d.path()});
  }
  std::sort(views.begin(), views.end(),
            [](const SegmentedView& a, const SegmentedView& b) { return a.index < b.index; });
  return views;
}

std::string resolve_id_map_folder(const fs::path& scene, const std::string& requested) {
  if (requested != "auto") return requested;
  const std::vector<std::string> candidates =
      id_map_folder_candidates(detect_dataset_layout(scene));
  std::vector<std::string> present;
  for (const std::string& c : candidates)
    if (fs::is_directory(scene / c)) present.push_back(c);
  if (present.empty())
    throw InputError(scene, fmt::format("no ID map folder: looked for {}/ (one ID map <image "
                                        "stem>.png per training view, docs/inputs.md)",
                                        fmt::join(candidates, "/, ")));
  if (present.size() > 1)
    spdlog::info("ID maps from {}/ (also present, not used: {}/; --id-maps chooses)", present[0],
                 fmt::join(present.begin() + 1, present.end(), "/, "));
  return present.front();
}

}  // namespace splat
