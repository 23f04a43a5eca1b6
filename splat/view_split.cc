#include "splat/view_split.h"

#include <filesystem>

#include "splat/error.h"

namespace splat {
namespace fs = std::filesystem;

ViewSplit split_views(const Scene& scene, SplitRule rule) {
  ViewSplit s;
  const fs::path train_dir = scene.root() / "images_train";
  if (rule == SplitRule::kAuto)
    rule = fs::is_directory(train_dir) ? SplitRule::kLerfMask : SplitRule::kEvery8;
  const auto& views = scene.views();
  for (size_t i = 0; i < views.size(); ++i) {
    bool test = false;
    if (rule == SplitRule::kLerfMask) test = !fs::exists(train_dir / views[i].name);
    if (rule == SplitRule::kEvery8) test = i % 8 == 0;
    (test ? s.test : s.train).push_back(i);
  }
  s.rule = rule == SplitRule::kLerfMask ? "lerf-mask (images_train/)"
           : rule == SplitRule::kEvery8 ? "every 8th view"
                                        : "all views";
  if (s.train.empty())
    throw InputError(train_dir, "no training views (images_train/ matches no image of the model)");
  return s;
}

}  // namespace splat
