#include "splat/view_split.h"

#include <filesystem>
#include <set>

#include "splat/dataset_layout.h"
#include "splat/error.h"

namespace splat {
namespace fs = std::filesystem;

namespace {

SplitRule rule_for_layout(DatasetLayout layout) {
  switch (layout) {
    case DatasetLayout::kLerfMask:
      return SplitRule::kLerfMask;
    case DatasetLayout::kOvsPrepared:
      return SplitRule::kSegmented;
    case DatasetLayout::kOvsOriginal:
      return SplitRule::kAll;
    case DatasetLayout::kPhotos:
      break;
  }
  return SplitRule::kEvery8;
}

// The image names of segmentations/<NN>/ (dataset_layout.h).
std::set<std::string> segmented_images(const fs::path& root) {
  if (!fs::is_directory(root / "segmentations"))
    throw InputError(root / "segmentations", "no segmentations/ folder to hold out");
  std::set<std::string> test;
  for (const SegmentedView& v : segmented_views(root)) test.insert(v.image);
  return test;
}

std::string rule_name(SplitRule rule) {
  switch (rule) {
    case SplitRule::kLerfMask:
      return "lerf-mask (images_train/)";
    case SplitRule::kSegmented:
      return "segmented views held out (segmentations/)";
    case SplitRule::kEvery8:
      return "every 8th view";
    default:
      break;
  }
  return "all views";
}

}  // namespace

ViewSplit split_views(const Scene& scene, SplitRule rule) {
  ViewSplit s;
  const fs::path train_dir = scene.root() / "images_train";
  if (rule == SplitRule::kAuto) rule = rule_for_layout(detect_dataset_layout(scene.root()));
  const std::set<std::string> segmented =
      rule == SplitRule::kSegmented ? segmented_images(scene.root()) : std::set<std::string>{};
  const auto& views = scene.views();
  for (size_t i = 0; i < views.size(); ++i) {
    bool test = false;
    if (rule == SplitRule::kLerfMask) test = !fs::exists(train_dir / views[i].name);
    if (rule == SplitRule::kSegmented) test = segmented.count(views[i].name) > 0;
    if (rule == SplitRule::kEvery8) test = i % 8 == 0;
    (test ? s.test : s.train).push_back(i);
  }
  s.rule = rule_name(rule);
  if (s.train.empty())
    throw InputError(rule == SplitRule::kLerfMask ? train_dir : scene.root(),
                     "no training views (the split '" + s.rule + "' leaves none)");
  return s;
}

}  // namespace splat
