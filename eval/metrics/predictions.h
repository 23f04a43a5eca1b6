#pragma once
// Predicted object masks of a view as the render stages write them, in one
// of two forms inside a prediction folder:
//   <stem>.png          a label map (8/16-bit IDs, 0 = background); the mask
//                       of object j is label == j (the baseline's form)
//   <stem>/<id>.png     one binary mask per object ID (op2gs-render's form,
//                       where objects may overlap)

#include <filesystem>
#include <string>

#include "eval/metrics/lerf_mask.h"

namespace eval {

// The predictions for the view with this image name. Throws splat::InputError
// naming the folder when it holds neither form.
ObjectMasks read_view_predictions(const std::filesystem::path& folder,
                                  const std::string& view_name);

}  // namespace eval
