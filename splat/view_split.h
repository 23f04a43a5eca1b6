#pragma once
// The train/test split of a scene's views. LERF-Mask names its training views
// in images_train/; prepared 3DOVS scenes hold out their segmented views (the
// fixed test frames); 3DOVS as released trains on every view; other scenes
// hold out every 8th view, as the reference 3DGS evaluation does
// (docs/evaluation.md).

#include <string>
#include <vector>

#include "splat/scene.h"

namespace splat {

enum class SplitRule { kAuto, kLerfMask, kSegmented, kEvery8, kAll };

// The training and test views of a scene under a split rule, by index into
// Scene::views() (sorted by name). kSegmented: the views with a
// segmentations/<NN>/ folder (NN indexes images/ sorted by name) are test
// views. kAuto follows the scene's layout (dataset_layout.h): images_train/ for
// LERF-Mask, the segmented views for prepared 3DOVS, all views for 3DOVS as
// released, else every 8th. Throws InputError when no view is left for
// training.
struct ViewSplit {
  std::vector<size_t> train, test;
  std::string rule;  // which rule was applied
};
ViewSplit split_views(const Scene& scene, SplitRule rule);

}  // namespace splat
