#include "splat/pose_file.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "splat/atomic_file.h"
#include "splat/camera.h"
#include "splat/error.h"

namespace splat {

std::vector<NamedPose> read_pose_file(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file, "cannot open the pose file");
  std::vector<NamedPose> poses;
  std::set<std::string> names;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    Eigen::Vector4d q;
    NamedPose p;
    fields >> q[0] >> q[1] >> q[2] >> q[3] >> p.t[0] >> p.t[1] >> p.t[2] >> std::ws;
    std::getline(fields, p.name);
    while (!p.name.empty() && (p.name.back() == '\r' || p.name.back() == ' ')) p.name.pop_back();
    const double norm = q.norm();
    if (p.name.empty() || !p.t.allFinite() || !(std::abs(norm - 1) < 1e-3))
      throw InputError(file, fmt::format("line {}: expected 'QW QX QY QZ TX TY TZ NAME' with a "
                                         "unit quaternion",
                                         number));
    if (!names.insert(p.name).second)
      throw InputError(file, fmt::format("line {}: image '{}' is given twice", number, p.name));
    p.R = rotation_from_quaternion(q / norm);
    poses.push_back(std::move(p));
  }
  return poses;
}

void write_pose_file(const std::filesystem::path& file, const std::vector<NamedPose>& poses) {
  std::string text =
      "# Refined camera poses, world-to-camera as in COLMAP's images.txt:\n"
      "# QW QX QY QZ TX TY TZ NAME\n";
  for (const NamedPose& p : poses) {
    const Eigen::Vector4d q = quaternion_from_rotation(p.R);
    text += fmt::format("{:.12g} {:.12g} {:.12g} {:.12g} {:.12g} {:.12g} {:.12g} {}\n", q[0], q[1],
                        q[2], q[3], p.t[0], p.t[1], p.t[2], p.name);
  }
  write_text_atomically(file, text);
}

std::filesystem::path choose_pose_file(const std::string& option,
                                       const std::vector<std::filesystem::path>& defaults) {
  if (option == "none") return {};
  if (!option.empty()) return option;
  for (const auto& file : defaults)
    if (std::filesystem::exists(file)) {
      spdlog::info("using the refined camera poses of {}", file.string());
      return file;
    }
  return {};
}

}  // namespace splat
