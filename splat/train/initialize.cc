#include "splat/train/initialize.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <nanoflann.hpp>

namespace splat {

namespace {

// nanoflann's dataset adaptor over a vector of points.
struct PointCloud {
  const std::vector<Eigen::Vector3d>& points;
  size_t kdtree_get_point_count() const { return points.size(); }
  double kdtree_get_pt(size_t i, size_t dim) const { return points[i][int(dim)]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};

using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointCloud>,
                                                   PointCloud, 3, size_t>;

}  // namespace

std::vector<double> mean_squared_knn_distance(const std::vector<Eigen::Vector3d>& points) {
  const size_t n = points.size();
  std::vector<double> result(n, 0.0);
  if (n < 2) return result;
  const PointCloud cloud{points};
  KdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  const size_t k = std::min<size_t>(4, n);  // the point itself and 3 neighbours
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    std::vector<size_t> index(k);
    std::vector<double> dist2(k);
    const size_t found = tree.knnSearch(points[i].data(), k, index.data(), dist2.data());
    // Skip the query point itself (distance 0, or a duplicate at distance 0).
    double sum = 0;
    size_t used = 0, self_skipped = 0;
    for (size_t j = 0; j < found; ++j) {
      if (index[j] == i && !self_skipped) {
        self_skipped = 1;
        continue;
      }
      if (used < 3) sum += dist2[j], ++used;
    }
    result[i] = used ? sum / double(used) : 0.0;
  });
  return result;
}

GaussianModel initialize_from_points(const std::vector<Eigen::Vector3d>& points,
                                     const std::vector<Eigen::Vector3f>& colors) {
  constexpr float kC0 = 0.28209479177387814f;
  GaussianModel m;
  m.resize(points.size());
  const std::vector<double> d2 = mean_squared_knn_distance(points);
  const float opacity_logit = std::log(0.1f / 0.9f);
  for (size_t i = 0; i < points.size(); ++i) {
    const float log_scale = float(std::log(std::sqrt(std::max(d2[i], 1e-7))));
    for (int k = 0; k < 3; ++k) {
      m.means[3 * i + k] = float(points[i][k]);
      m.sh_dc[3 * i + k] = (colors[i][k] - 0.5f) / kC0;
      m.log_scales[3 * i + k] = log_scale;
    }
    m.rotations[4 * i] = 1.f;
    m.opacity_logits[i] = opacity_logit;
  }
  return m;
}

}  // namespace splat
