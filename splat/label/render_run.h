#pragma once
// What op2gs-render writes for chosen views (test views by default) or a
// camera path, into an output folder:
//
//   rgb/<stem>.png                 colour
//   masks/<stem>/<id>.png          binary mask of object id: S_id > tau (for
//                                  the evaluation; 0 / 255)
//   masks_color/<stem>.png         every object's mask in its colour, to look at
//   occupancy/<stem>/<id>.png      S_id as grey (with --occupancy)
//   objects/<stem>/<id>.png        the colour image inside the object's mask
//                                  (with --object-images)
//   instance_labels/<stem>.png     argmax alpha* label map (16-bit IDs), and
//                                  instance_labels_color/
//   baseline_labels/<stem>.png     argmax alpha_i T_i label map (the
//                                  ablation's baseline), and baseline_labels_color/
//   timing.json                    mask rendering against colour rendering
//   photo/masks/<stem>/<id>.png,   with --photo-geometry: the masks and the
//   photo/instance_labels/<stem>.png  label map moved into the geometry of
//                                  the view's photo (<scene>/photo_cameras/,
//                                  which op2gs-sfm writes when it undistorts;
//                                  with --photo-geometry=auto, only then)
//
// The object operations on the model itself are in object_ply.h.

#include <filesystem>
#include <string>
#include <vector>

#include "splat/render/pose_fit.h"
#include "splat/scene.h"
#include "splat/view_split.h"

namespace splat {

enum class RenderViews { kTest, kTrain, kAll };

// Whether to also write masks in the geometry of the photos. kAuto does so
// when the scene has the photos' cameras, that is when op2gs-sfm undistorted
// the photos; otherwise the views are the photos and there is nothing to add.
enum class PhotoGeometryMode { kOff, kOn, kAuto };

struct RenderRunOptions {
  SceneOptions scene;
  SplitRule split = SplitRule::kAuto;
  RenderViews views = RenderViews::kTest;
  std::vector<std::string> view_names;  // if not empty: these views instead
  // A COLMAP model folder whose images are the cameras of a path to render
  // instead of the scene's views (no image files needed).
  std::filesystem::path camera_path;
  std::filesystem::path model;   // checkpoint or PLY with both OP2GS properties
  std::vector<int32_t> objects;  // only these objects (default: all)
  float tau = 0.5f;              // mask threshold on S_j
  bool occupancy = false;
  bool object_images = false;
  float background[3] = {0, 0, 0};
  // Also write the masks and the instance label map of the scene's views in
  // the geometry of their photos, to lay over the photos themselves.
  PhotoGeometryMode photo_geometry = PhotoGeometryMode::kOff;
  // The camera of every scene view without a refined pose (scene.poses)
  // fitted to its photo first, the model held fixed: the test views of a
  // model trained with --refine-poses. Written to fitted_poses.txt.
  PoseFitOptions fit_poses;
  void Check() const;  // throws std::invalid_argument
};

struct RenderTiming {
  size_t views = 0;
  double color_ms = 0;      // mean per view: colour render
  double masks_ms = 0;      // mean per view: all-object occupancy maps, no colour
  double label_map_ms = 0;  // mean per view: the instance label map, no colour
};

RenderTiming run_render(const std::filesystem::path& scene_dir, const std::filesystem::path& out,
                        const RenderRunOptions& options);

}  // namespace splat
