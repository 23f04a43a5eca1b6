#include "splat/sfm/llff.h"

#include <fmt/format.h>

#include "splat/camera.h"
#include "splat/error.h"
#include "splat/npy.h"

namespace splat {

ColmapModel llff_to_colmap(const std::filesystem::path& file, const std::vector<std::string>& names,
                           int width, int height) {
  std::vector<size_t> shape;
  const std::vector<double> v = read_npy(file, &shape);
  if (shape.size() != 2 || shape[1] != 17)
    throw InputError(file, "poses_bounds.npy must have shape (N, 17)");
  if (shape[0] != names.size())
    throw InputError(file, fmt::format("{} poses for {} images", shape[0], names.size()));
  ColmapModel model;
  const double* first = v.data();
  const double llff_h = first[4], llff_w = first[9], f = first[14];
  if (!(llff_h > 0 && llff_w > 0 && f > 0)) throw InputError(file, "no valid H, W, focal");
  const double scale = double(width) / llff_w;
  if (std::abs(llff_h * scale - height) > 1.0 + scale)
    throw InputError(file, fmt::format("poses are for {}x{} images, the images are {}x{} (another "
                                       "aspect ratio)",
                                       llff_w, llff_h, width, height));
  model.cameras[1] = {
      1, 1, uint64_t(width), uint64_t(height), {f * scale, f * scale, width / 2.0, height / 2.0}};
  for (size_t i = 0; i < names.size(); ++i) {
    const double* row = &v[17 * i];
    auto m = [&](int r, int c) { return row[5 * r + c]; };
    Eigen::Matrix3d c2w;
    for (int r = 0; r < 3; ++r) {
      c2w(r, 0) = m(r, 1);   // right
      c2w(r, 1) = m(r, 0);   // down
      c2w(r, 2) = -m(r, 2);  // forward
    }
    const Eigen::Vector3d center(m(0, 3), m(1, 3), m(2, 3));
    const Eigen::Matrix3d R = c2w.transpose();
    ColmapImage image;
    image.image_id = uint32_t(i + 1);
    image.camera_id = 1;
    image.name = names[i];
    image.qvec = quaternion_from_rotation(R);
    image.tvec = -R * center;
    model.images[image.image_id] = image;
  }
  return model;
}

}  // namespace splat
