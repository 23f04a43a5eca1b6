#pragma once
// Renders are made in the undistorted pinhole views that op2gs-sfm makes,
// but the ground truth of a scene whose photos had lens distortion is drawn
// on the photos. op2gs-sfm records the photos' cameras in
// <scene>/photo_cameras/ when it undistorts; with them, predicted masks are
// resampled into the photos' geometry before they are scored (nearest
// neighbour, the way the ID maps went the other way). Scenes without that
// folder (pinhole photos, the public benchmarks) are scored as they are.

#include <filesystem>
#include <string>

#include "eval/metrics/lerf_mask.h"
#include "splat/photo_cameras.h"

namespace eval {

class PhotoGeometry {
 public:
  // Reads <scene>/photo_cameras/ and <scene>/sparse/0/ when the first exists.
  explicit PhotoGeometry(const std::filesystem::path& scene);

  bool active() const { return !cameras_.empty(); }

  // The masks of the view with this image name, moved from the undistorted
  // view (at its size or a downscaled one) into the photo, at the photo's
  // size. Unchanged when inactive or when either model lacks the view.
  ObjectMasks to_photo(const std::string& view_name, ObjectMasks masks) const;

 private:
  splat::PhotoCameras cameras_;
};

}  // namespace eval
