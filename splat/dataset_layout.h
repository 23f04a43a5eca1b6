#pragma once
// What kind of scene folder a scene is, told from the files in it, so that
// the benchmarks are read exactly as downloaded (docs/inputs.md):
//
//   LERF-Mask (Gaussian Grouping's download): images_train/ or test_mask/;
//     DEVA ID maps in object_mask/.
//   3DOVS as released: segmentations/ and LLFF poses; every view trains.
//   3DOVS as the 3DGS papers prepare it (ObjectGS): segmentations/ beside
//     object_mask_deva/ (DEVA ID maps) and sparse/0/; the segmented views
//     are the fixed test frames, held out of training.
//   Photos: anything else; SAM2 ID maps in sam2/.
//
// The layout decides the defaults of the train/test split (view_split.h) and
// of the ID map folder; an explicit option always wins.

#include <filesystem>
#include <string>
#include <vector>

namespace splat {

enum class DatasetLayout { kLerfMask, kOvsOriginal, kOvsPrepared, kPhotos };

// The layout of a scene folder (the user's, or the one op2gs-sfm made, which
// links the user's files).
DatasetLayout detect_dataset_layout(const std::filesystem::path& scene);

// "lerf-mask", "3dovs", "3dovs-prepared", "photos".
std::string layout_name(DatasetLayout layout);
// One line for logs and reports: the layout and what follows from it.
std::string layout_description(DatasetLayout layout);

// The ID map folder names op2gs knows, in the order a layout prefers them:
// object_mask/ first for LERF-Mask, object_mask_deva/ for prepared 3DOVS,
// sam2/ otherwise.
std::vector<std::string> id_map_folder_candidates(DatasetLayout layout);

// The 3DOVS ground truth's view indexing: segmentations/<NN>/ holds the masks
// of the NN-th file of images/ sorted by name.
struct SegmentedView {
  size_t index = 0;             // into image_names(scene)
  std::string image;            // its file name
  std::filesystem::path masks;  // segmentations/<NN>/
};
// The files of <scene>/images/, sorted by name.
std::vector<std::string> sorted_image_names(const std::filesystem::path& scene);
// The segmented views, by index. Throws InputError naming the folder when a
// folder of segmentations/ is not an image index or indexes no image.
std::vector<SegmentedView> segmented_views(const std::filesystem::path& scene);

// The ID map folder of a scene: `requested` itself unless it is "auto";
// with "auto", the first of the layout's candidates that exists. Throws
// InputError naming the scene and every folder looked for when none exists.
std::string resolve_id_map_folder(const std::filesystem::path& scene, const std::string& requested);

}  // namespace splat
