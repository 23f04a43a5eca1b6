#pragma once
// Posed captures in the transforms.json form of nerfstudio (ns-process-data,
// Polycam and Record3D exports) and instant-ngp, read into a COLMAP model so
// that op2gs-sfm imports them as it imports a COLMAP folder (docs/inputs.md).
//
// What is read:
//   - intrinsics at the top level, overridden per frame: fl_x fl_y cx cy w h,
//     or instant-ngp's camera_angle_x (and _y); distortion k1 k2 k3 k4 p1 p2
//     with camera_model PINHOLE, OPENCV or OPENCV_FISHEYE (without
//     camera_model: OPENCV when any coefficient is set, OPENCV_FISHEYE when
//     is_fisheye is true);
//   - each frame's transform_matrix, camera to world in the OpenGL convention
//     (x right, y up, z back), turned into COLMAP's world to camera (x right,
//     y down, z forward). The world frame is kept as it is: nerfstudio writes
//     its applied_transform into the poses and the points alike;
//   - file_path relative to the file's folder, with or without extension;
//     frames whose photo is missing are skipped and listed;
//   - points from ply_file_path (nerfstudio's sparse_pc.ply), when given or
//     present beside the file.
// Ignored: aabb_scale, scale, offset, sharpness and other training hints.

#include <filesystem>
#include <string>
#include <vector>

#include "splat/colmap_model.h"

namespace splat {

struct TransformsCapture {
  // Cameras (one per distinct intrinsics), the frames' poses, and the points
  // of the PLY when there is one (without tracks).
  ColmapModel model;
  bool has_points = false;
  std::filesystem::path points_file;  // where the points came from
  // Frames listed whose photo is not there (file_path as written).
  std::vector<std::string> missing;
  std::string flavour;             // "nerfstudio" or "instant-ngp"
  bool applied_transform = false;  // nerfstudio's, already in the poses and points
};

// Reads `file`; image names in the model are relative to `images_dir`, where
// every frame's photo must be. Throws InputError naming the file for
// malformed JSON, a frame without a valid pose, intrinsics that are missing
// or that no COLMAP camera model expresses, or a photo whose size differs
// from its frame's w x h.
TransformsCapture read_transforms_json(const std::filesystem::path& file,
                                       const std::filesystem::path& images_dir);

}  // namespace splat
