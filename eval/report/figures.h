#pragma once
// The report's figures (HTML): per test view and query the photo, the
// ground truth and each prediction's mask coloured by error, the instance
// label map, and the training curves.

#include <string>

#include "eval/report/scene_data.h"

namespace eval {

// Every test view's panels; `width` is a panel's width in pixels.
std::string scene_figures(const SceneData& s, int width);

// The training curves' PNGs, or nothing when there are none.
std::string curves_html(const SceneData& s, int width);

}  // namespace eval
