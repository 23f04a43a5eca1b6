#pragma once
// A Gaussian model from SfM points, as the reference initialises it:
// SH DC from the point colour ((rgb - 0.5) / C0), the rest zero, opacity
// logit of 0.1, isotropic scale log(sqrt(mean squared distance to the 3
// nearest neighbours)) (at least 1e-7 squared), identity rotation.

#include <Eigen/Core>
#include <vector>

#include "splat/gaussians.h"

namespace splat {

GaussianModel initialize_from_points(const std::vector<Eigen::Vector3d>& points,
                                     const std::vector<Eigen::Vector3f>& colors);

// Mean squared distance of each point to its 3 nearest other points.
std::vector<double> mean_squared_knn_distance(const std::vector<Eigen::Vector3d>& points);

}  // namespace splat
