#include "splat/sfm/alignment.h"

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>

#include "splat/camera.h"
#include "splat/error.h"

namespace splat {

Similarity align_similarity(const std::vector<Eigen::Vector3d>& from,
                            const std::vector<Eigen::Vector3d>& to) {
  if (from.size() != to.size() || from.size() < 3)
    throw std::invalid_argument("alignment needs at least 3 corresponding points");
  Eigen::Matrix3Xd a(3, from.size()), b(3, to.size());
  for (size_t i = 0; i < from.size(); ++i) a.col(long(i)) = from[i], b.col(long(i)) = to[i];
  const Eigen::Matrix4d T = Eigen::umeyama(a, b, true);
  Similarity s;
  s.scale = T.block<3, 3>(0, 0).col(0).norm();
  if (!(s.scale > 0) || !std::isfinite(s.scale))
    throw std::invalid_argument("alignment is degenerate (points on a line?)");
  s.R = T.block<3, 3>(0, 0) / s.scale;
  s.t = T.block<3, 1>(0, 3);
  return s;
}

PoseAccuracy pose_accuracy(const ColmapModel& estimated, const ColmapModel& truth) {
  std::map<std::string, const ColmapImage*> true_by_name;
  for (const auto& [id, image] : truth.images) true_by_name[image.name] = &image;
  std::vector<Eigen::Vector3d> from, to;
  std::vector<Eigen::Matrix3d> est_R, true_R;
  for (const auto& [id, image] : estimated.images) {
    const auto it = true_by_name.find(image.name);
    if (it == true_by_name.end()) continue;
    const Eigen::Matrix3d Re = rotation_from_quaternion(image.qvec);
    const Eigen::Matrix3d Rt = rotation_from_quaternion(it->second->qvec);
    from.push_back(-Re.transpose() * image.tvec);
    to.push_back(-Rt.transpose() * it->second->tvec);
    est_R.push_back(Re);
    true_R.push_back(Rt);
  }
  PoseAccuracy acc;
  acc.matched = from.size();
  acc.alignment = align_similarity(from, to);
  double sq = 0, angle = 0;
  for (size_t i = 0; i < from.size(); ++i) {
    sq += (acc.alignment.apply(from[i]) - to[i]).squaredNorm();
    // World-to-camera rotation in the true frame: R_est * R_align^T.
    const Eigen::Matrix3d aligned = est_R[i] * acc.alignment.R.transpose();
    const Eigen::AngleAxisd diff(aligned * true_R[i].transpose());
    angle += std::abs(diff.angle());
  }
  acc.center_rmse = std::sqrt(sq / double(from.size()));
  acc.rotation_error_deg = angle / double(from.size()) * 180.0 / M_PI;
  return acc;
}

PoseAccuracy pose_accuracy_against(const ColmapModel& estimated,
                                   const std::filesystem::path& truth_model) {
  const ColmapModel truth = read_colmap_model(truth_model);
  std::set<std::string> true_names;
  for (const auto& [id, image] : truth.images) true_names.insert(image.name);
  size_t shared = 0;
  for (const auto& [id, image] : estimated.images) shared += true_names.count(image.name);
  if (shared < 3)
    throw InputError(truth_model, "the true model shares fewer than 3 image names with the scene");
  return pose_accuracy(estimated, truth);
}

}  // namespace splat
