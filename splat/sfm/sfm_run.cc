#include "splat/sfm/sfm_run.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>

#include "splat/atomic_file.h"
#include "splat/colmap_model.h"
#include "splat/error.h"
#include "splat/sfm/alignment.h"

namespace splat {
namespace fs = std::filesystem;
using json = nlohmann::json;

void SfmOptions::Check() const {
  if (sequential_overlap < 1) throw std::invalid_argument("sequential overlap must be >= 1");
  if (!intrinsics.empty() && intrinsics.size() != 4)
    throw std::invalid_argument("known intrinsics are four numbers: fx fy cx cy");
  if (!(min_registered_fraction >= 0 && min_registered_fraction <= 1))
    throw std::invalid_argument("the minimum registered share must be in [0, 1]");
  if (!vocab_tree.empty() && !fs::is_regular_file(vocab_tree))
    throw InputError(vocab_tree, "vocabulary tree not found");
  if (threads < 0) throw std::invalid_argument("threads must be >= 0");
}

namespace {

bool is_image(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".tif" || ext == ".tiff";
}

std::vector<std::string> image_names(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw InputError(dir, "no image folder");
  std::vector<std::string> names;
  for (const auto& f : fs::directory_iterator(dir))
    if (f.is_regular_file() && is_image(f.path())) names.push_back(f.path().filename().string());
  std::sort(names.begin(), names.end());
  if (names.size() < 2) throw InputError(dir, "SfM needs at least two images");
  return names;
}

// Each finished step leaves a marker holding a fingerprint of its inputs and
// options; a rerun with the same fingerprint skips the step.
class Steps {
 public:
  explicit Steps(fs::path out) : out_(std::move(out)) {}
  // Runs `body` unless the step finished with this fingerprint. Returns true
  // if it ran (so later steps must rerun too).
  bool run(const std::string& step, const std::string& fingerprint, bool force,
           const std::function<void()>& body) {
    const fs::path marker = out_ / (".done_" + step);
    if (!force && fs::exists(marker) && read_text_file(marker) == fingerprint) {
      spdlog::info("{}: done before, reused", step);
      return false;
    }
    fs::remove(marker);
    spdlog::info("{} ...", step);
    body();
    write_text_atomically(marker, fingerprint);
    return true;
  }

 private:
  fs::path out_;
};

bool want_gpu(const SfmOptions& o) {
  if (o.gpu != SfmOptions::Gpu::kAuto) return o.gpu == SfmOptions::Gpu::kOn;
  bool cuda = false;
  o.colmap.available(&cuda);
  return cuda && fs::exists("/dev/nvidia0");
}

std::string join(const std::vector<double>& v) {
  std::string s;
  for (double x : v) s += (s.empty() ? "" : ",") + fmt::format("{}", x);
  return s;
}

// The index and image count of the model with the most registered images.
std::pair<int, size_t> largest_model(const fs::path& sparse_raw, size_t* models) {
  int best = -1;
  size_t best_images = 0;
  *models = 0;
  for (int k = 0; fs::is_directory(sparse_raw / std::to_string(k)); ++k) {
    ++*models;
    const size_t n = read_colmap_model(sparse_raw / std::to_string(k)).images.size();
    if (n > best_images) best = k, best_images = n;
  }
  return {best, best_images};
}

bool is_pinhole(const ColmapModel& m) {
  for (const auto& [id, c] : m.cameras)
    if (c.model_id != 0 && c.model_id != 1) return false;  // SIMPLE_PINHOLE, PINHOLE
  return true;
}

// Links everything else the user's scene folder holds (ID maps, the
// LERF-Mask and 3DOVS benchmark files) into the output scene, so the next
// stages find it there.
void link_user_files(const fs::path& user, const fs::path& scene, const std::string& images) {
  const std::set<std::string> own = {images, "sparse", "images_2", "images_4", "images_8"};
  for (const auto& f : fs::directory_iterator(user)) {
    const std::string name = f.path().filename().string();
    if (own.count(name) || fs::exists(fs::symlink_status(scene / name))) continue;
    fs::create_symlink(fs::absolute(f.path()), scene / name);
  }
}

// Replaces `link` with a symbolic link to `target`.
void relink(const fs::path& target, const fs::path& link) {
  fs::remove_all(link);
  fs::create_directories(link.parent_path());
  fs::create_directory_symlink(fs::absolute(target), link);
}

}  // namespace

SfmResult run_sfm(const fs::path& scene_dir, const fs::path& out, const SfmOptions& options) {
  options.Check();
  SfmOptions o = options;
  fs::create_directories(out);
  o.colmap.log_file = out / "colmap.log";
  if (!o.colmap.available())
    throw ColmapError(
        fmt::format("`{}` does not run: install COLMAP with `apt-get install "
                    "colmap` (scripts/setup.sh does), or give its path with --colmap",
                    o.colmap.binary));
  const fs::path images = scene_dir / o.images_dir;
  const std::vector<std::string> names = image_names(images);
  const fs::path db = out / "database.db", raw = out / "sparse_raw", und = out / "undistorted";
  const bool gpu = want_gpu(o);
  const std::string use_gpu = gpu ? "1" : "0";
  Steps steps(out);
  std::string fp = fmt::format("images {}\n", fmt::join(names, "\n"));
  bool redo = false;

  if (!o.import_model.empty()) {
    const ColmapModel imported = read_colmap_model(o.import_model);
    fs::remove_all(raw);
    write_colmap_model(imported, raw / "0", ColmapFormat::kBinary);
    fp += "import " + fs::absolute(o.import_model).string();
    redo = true;
  } else {
    const bool known = !o.intrinsics.empty();
    fp += fmt::format("camera {} single {} known {}\n", known ? "PINHOLE" : o.camera_model,
                      o.single_camera, join(o.intrinsics));
    redo = steps.run("feature extraction", fp, redo, [&] {
      fs::remove(db);
      std::vector<std::string> args = {"--database_path",
                                       db.string(),
                                       "--image_path",
                                       images.string(),
                                       "--ImageReader.single_camera",
                                       o.single_camera ? "1" : "0",
                                       "--ImageReader.camera_model",
                                       known ? "PINHOLE" : o.camera_model,
                                       "--SiftExtraction.use_gpu",
                                       use_gpu};
      if (known) args.insert(args.end(), {"--ImageReader.camera_params", join(o.intrinsics)});
      if (o.threads)
        args.insert(args.end(), {"--SiftExtraction.num_threads", std::to_string(o.threads)});
      o.colmap.run("feature extraction", "feature_extractor", args);
    });
    const bool sequential = o.matcher == SfmMatcher::kSequential ||
                            (o.matcher == SfmMatcher::kAuto && names.size() > 250);
    fp += fmt::format("matcher {} overlap {} vocab {}\n", sequential ? "sequential" : "exhaustive",
                      o.sequential_overlap, o.vocab_tree.string());
    redo = steps.run("matching", fp, redo, [&] {
      std::vector<std::string> args = {"--database_path", db.string(), "--SiftMatching.use_gpu",
                                       use_gpu};
      if (sequential) {
        args.insert(args.end(),
                    {"--SequentialMatching.overlap", std::to_string(o.sequential_overlap),
                     "--SequentialMatching.loop_detection", o.vocab_tree.empty() ? "0" : "1"});
        if (!o.vocab_tree.empty())
          args.insert(args.end(), {"--SequentialMatching.vocab_tree_path", o.vocab_tree.string()});
      }
      o.colmap.run("matching", sequential ? "sequential_matcher" : "exhaustive_matcher", args);
    });
    redo = steps.run("mapping", fp, redo, [&] {
      fs::remove_all(raw);
      fs::create_directories(raw);
      std::vector<std::string> args = {"--database_path", db.string(),     "--image_path",
                                       images.string(),   "--output_path", raw.string()};
      if (known)
        args.insert(args.end(),
                    {"--Mapper.ba_refine_focal_length", "0", "--Mapper.ba_refine_principal_point",
                     "0", "--Mapper.ba_refine_extra_params", "0"});
      if (o.threads) args.insert(args.end(), {"--Mapper.num_threads", std::to_string(o.threads)});
      o.colmap.run("mapping", "mapper", args);
    });
  }

  SfmResult r;
  r.views = names.size();
  const auto [kept, registered] = largest_model(raw, &r.models);
  if (kept < 0)
    throw ColmapError("mapping made no model: no two views could be matched; log " +
                      o.colmap.log_file.string());
  r.kept_model = kept;
  r.registered = registered;
  const ColmapModel model = read_colmap_model(raw / std::to_string(kept));
  std::set<std::string> in_model;
  for (const auto& [id, image] : model.images) in_model.insert(image.name);
  for (const std::string& n : names)
    if (!in_model.count(n)) r.unregistered.push_back(n);
  spdlog::info("{} of {} views registered ({} model{}; kept model {})", r.registered, r.views,
               r.models, r.models == 1 ? "" : "s", kept);
  if (!r.unregistered.empty()) spdlog::warn("not registered: {}", fmt::join(r.unregistered, ", "));
  const double share = double(r.registered) / double(r.views);
  if (r.registered < 2 || share < o.min_registered_fraction)
    throw ColmapError(
        fmt::format("only {} of {} views registered (minimum {:.0f}%); try "
                    "--matcher exhaustive, more overlapping photos, or known "
                    "intrinsics",
                    r.registered, r.views, 100 * o.min_registered_fraction));

  // Undistortion into PINHOLE, and the scene layout the trainer reads.
  r.scene = out / "scene";
  const fs::path sparse = r.scene / "sparse" / "0";
  fp += fmt::format("kept {}\n", kept);
  steps.run("undistortion", fp, redo, [&] {
    fs::remove_all(r.scene);
    fs::create_directories(sparse);
    if (is_pinhole(model)) {  // nothing to undistort
      write_colmap_model(model, sparse, ColmapFormat::kBinary);
      relink(images, r.scene / "images");
      return;
    }
    fs::remove_all(und);
    o.colmap.run(
        "undistortion", "image_undistorter",
        {"--image_path", images.string(), "--input_path", (raw / std::to_string(kept)).string(),
         "--output_path", und.string(), "--output_type", "COLMAP"});
    write_colmap_model(read_colmap_model(und / "sparse"), sparse, ColmapFormat::kBinary);
    relink(und / "images", r.scene / "images");
  });
  link_user_files(scene_dir, r.scene, o.images_dir);

  json accuracy = nullptr;
  if (!o.truth.empty()) {
    const PoseAccuracy acc = pose_accuracy(model, read_colmap_model(o.truth));
    r.center_rmse = acc.center_rmse;
    r.rotation_error_deg = acc.rotation_error_deg;
    accuracy = {{"matched", acc.matched},
                {"center_rmse", acc.center_rmse},
                {"rotation_error_deg", acc.rotation_error_deg},
                {"scale", acc.alignment.scale}};
    spdlog::info("against the true cameras: centre RMSE {:.5f}, rotation error {:.3f} deg",
                 acc.center_rmse, acc.rotation_error_deg);
  }
  const json summary = {{"pose_accuracy", accuracy},
                        {"views", r.views},
                        {"registered", r.registered},
                        {"unregistered", r.unregistered},
                        {"models", r.models},
                        {"kept_model", kept},
                        {"points", model.points3d.size()},
                        {"gpu", gpu},
                        {"imported", o.import_model.string()}};
  write_text_atomically(out / "sfm.json", summary.dump(2) + "\n");
  return r;
}

}  // namespace splat
