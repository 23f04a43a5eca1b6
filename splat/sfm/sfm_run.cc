#include "splat/sfm/sfm_run.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>

#include "splat/atomic_file.h"
#include "splat/colmap_model.h"
#include "splat/error.h"
#include "splat/image.h"
#include "splat/photo_cameras.h"
#include "splat/sfm/alignment.h"
#include "splat/sfm/colmap_database.h"
#include "splat/sfm/llff.h"
#include "splat/sfm/undistort_id_maps.h"

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
  // Each is replaced inside <out>/scene/: a plain folder name, never a path.
  for (const std::string& dir : id_map_dirs)
    if (dir.empty() || dir == "." || dir == ".." || dir.find('/') != std::string::npos ||
        dir == images_dir || dir == "sparse")
      throw std::invalid_argument(
          fmt::format("--id-map-dirs: '{}' is not a folder name of the scene", dir));
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

// colmap_has_cuda: what ColmapCommand::available found.
bool want_gpu(const SfmOptions& o, bool colmap_has_cuda) {
  if (o.gpu != SfmOptions::Gpu::kAuto) return o.gpu == SfmOptions::Gpu::kOn;
  return colmap_has_cuda && fs::exists("/dev/nvidia0");
}

// "1,2.5,3": COLMAP's list syntax for camera parameters.
std::string join(const std::vector<double>& v) { return fmt::format("{}", fmt::join(v, ",")); }

// The model with the most registered images, and its index (-1 if there is
// no model).
std::pair<int, ColmapModel> largest_model(const fs::path& sparse_raw, size_t* models) {
  std::pair<int, ColmapModel> best{-1, {}};
  *models = 0;
  for (int k = 0; fs::is_directory(sparse_raw / std::to_string(k)); ++k) {
    ++*models;
    ColmapModel m = read_colmap_model(sparse_raw / std::to_string(k));
    if (m.images.size() > best.second.images.size()) best = {k, std::move(m)};
  }
  return best;
}

bool is_pinhole(const ColmapModel& m) {
  for (const auto& [id, c] : m.cameras)
    if (c.model_id != 0 && c.model_id != 1) return false;  // SIMPLE_PINHOLE, PINHOLE
  return true;
}

// Links everything else the user's scene folder holds (ID maps, the
// LERF-Mask and 3DOVS benchmark files) into the output scene, so the next
// stages find it there. The user's downscaled copies (images_2/ ...) are
// linked only when the views were not undistorted: they have the photos'
// geometry.
void link_user_files(const fs::path& user, const fs::path& scene, const std::string& images,
                     bool undistorted) {
  std::set<std::string> own = {images, "sparse"};
  if (undistorted) own.insert({"images_2", "images_4", "images_8"});
  for (const auto& f : fs::directory_iterator(user)) {
    const std::string name = f.path().filename().string();
    if (own.count(name) || fs::exists(fs::symlink_status(scene / name))) continue;
    fs::create_symlink(fs::absolute(f.path()), scene / name);
  }
}

// The ID maps of the user's photos, resampled as COLMAP undistorted the
// photos (the undistorted views are cropped and re-centred). Always redone:
// it is quick, and the user may have replaced the maps since the last run.
void undistort_user_id_maps(const fs::path& user, const fs::path& scene,
                            const ColmapModel& distorted, const SfmOptions& o) {
  const ColmapModel undistorted = read_colmap_model(scene / "sparse" / "0");
  for (const std::string& folder : o.id_map_dirs) {
    if (!fs::is_directory(user / folder)) continue;
    const size_t n = undistort_id_map_folder(user / folder, scene / folder, distorted, undistorted);
    spdlog::info("{}/: {} ID maps undistorted with the images", folder, n);
  }
  for (const char* truth : {"test_mask", "segmentations"})
    if (fs::exists(user / truth))
      spdlog::warn(
          "{}/ is linked as it is: its masks have the geometry of the original photos; "
          "op2gs-eval resamples the renders into it ({}/)",
          truth, kPhotoCamerasDir);
}

// The cameras and poses of a model, without its points and observations.
ColmapModel cameras_only(ColmapModel model) {
  model.points3d.clear();
  for (auto& [id, image] : model.images) image.points2d.clear(), image.point3d_ids.clear();
  return model;
}

// A model given with --import: every image it names must be in the scene's
// image folder, or the undistorter and the trainer would fail later.
ColmapModel read_imported_model(const fs::path& model_dir, const fs::path& images) {
  ColmapModel model = read_colmap_model(model_dir);
  if (model.images.empty()) throw InputError(model_dir, "the model has no images");
  for (const auto& [id, image] : model.images)
    if (!fs::is_regular_file(images / image.name))
      throw InputError(model_dir, fmt::format("image {} of the model is not in {}", image.name,
                                              images.string()));
  return model;
}

// Replaces `link` with a symbolic link to `target`.
void relink(const fs::path& target, const fs::path& link) {
  fs::remove_all(link);
  fs::create_directories(link.parent_path());
  fs::create_directory_symlink(fs::absolute(target), link);
}

// The model with the image and camera IDs the database gave its images (the
// feature extractor numbers them in the order its threads finish).
ColmapModel with_database_ids(const ColmapModel& model, const fs::path& db) {
  const auto ids = read_database_images(db);
  ColmapModel out;
  for (const auto& [id, image] : model.images) {
    const auto it = ids.find(image.name);
    if (it == ids.end()) throw InputError(db, "the database has no image " + image.name);
    ColmapImage copy = image;
    copy.image_id = it->second.image_id;
    copy.camera_id = it->second.camera_id;
    ColmapCamera camera = model.cameras.at(image.camera_id);
    camera.camera_id = copy.camera_id;
    out.cameras[camera.camera_id] = camera;
    out.images[copy.image_id] = copy;
  }
  return out;
}

}  // namespace

SfmResult run_sfm(const fs::path& scene_dir, const fs::path& out, const SfmOptions& options) {
  options.Check();
  SfmOptions o = options;
  fs::create_directories(out);
  o.colmap.log_file = out / "colmap.log";
  const fs::path images = scene_dir / o.images_dir;
  const std::vector<std::string> names = image_names(images);
  // An imported pinhole model needs no COLMAP at all.
  std::optional<ColmapModel> imported;
  if (!o.import_model.empty()) imported = read_imported_model(o.import_model, images);
  const bool needs_colmap = !imported || !is_pinhole(*imported);
  bool cuda = false;
  if (needs_colmap && !o.colmap.available(&cuda))
    throw ColmapError(
        fmt::format("`{}` does not run: install COLMAP with `apt-get install "
                    "colmap` (scripts/setup.sh does), or give its path with --colmap",
                    o.colmap.binary));
  const fs::path db = out / "database.db", raw = out / "sparse_raw", und = out / "undistorted";
  const bool gpu = want_gpu(o, cuda);
  const std::string use_gpu = gpu ? "1" : "0";
  Steps steps(out);
  std::string fp = fmt::format("images {}\n", fmt::join(names, "\n"));
  bool redo = false;

  const auto extract = [&](const std::string& model, const std::vector<double>& params) {
    fs::remove(db);
    std::vector<std::string> args = {"--database_path",
                                     db.string(),
                                     "--image_path",
                                     images.string(),
                                     "--ImageReader.single_camera",
                                     o.single_camera || !params.empty() ? "1" : "0",
                                     "--ImageReader.camera_model",
                                     model,
                                     "--SiftExtraction.use_gpu",
                                     use_gpu};
    if (!params.empty()) args.insert(args.end(), {"--ImageReader.camera_params", join(params)});
    if (o.threads)
      args.insert(args.end(), {"--SiftExtraction.num_threads", std::to_string(o.threads)});
    o.colmap.run("feature extraction", "feature_extractor", args);
  };
  const bool sequential = o.matcher == SfmMatcher::kSequential ||
                          (o.matcher == SfmMatcher::kAuto && names.size() > 250);
  const auto match = [&] {
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
  };
  // Bundle adjustment leaves known intrinsics as they are.
  const std::vector<std::string> fixed_intrinsics = {"--Mapper.ba_refine_focal_length",    "0",
                                                     "--Mapper.ba_refine_principal_point", "0",
                                                     "--Mapper.ba_refine_extra_params",    "0"};
  const std::string matcher_fp =
      fmt::format("matcher {} overlap {} vocab {}\n", sequential ? "sequential" : "exhaustive",
                  o.sequential_overlap, o.vocab_tree.string());

  if (imported) {
    fs::remove_all(raw);
    write_colmap_model(*imported, raw / "0", ColmapFormat::kBinary);
    fp += "import " + fs::absolute(o.import_model).string();
    redo = true;
  } else if (o.llff) {
    // Known poses: features and matches, then COLMAP triangulates the points
    // with the cameras held fixed.
    const ImageRGB first = read_image_rgb(images / names.front());
    const ColmapModel known =
        llff_to_colmap(scene_dir / "poses_bounds.npy", names, first.width, first.height);
    const std::vector<double>& params = known.cameras.at(1).params;
    fp += fmt::format("llff {}\n", join(params));
    redo = steps.run("feature extraction", fp, redo, [&] { extract("PINHOLE", params); });
    fp += matcher_fp;
    redo = steps.run("matching", fp, redo, match);
    redo = steps.run("triangulation", fp, redo, [&] {
      fs::remove_all(raw);
      fs::create_directories(raw / "0");
      write_colmap_model(with_database_ids(known, db), out / "llff_model", ColmapFormat::kText);
      std::vector<std::string> args = {"--database_path", db.string(),
                                       "--image_path",    images.string(),
                                       "--input_path",    (out / "llff_model").string(),
                                       "--output_path",   (raw / "0").string()};
      args.insert(args.end(), fixed_intrinsics.begin(), fixed_intrinsics.end());
      o.colmap.run("triangulation", "point_triangulator", args);
    });
  } else {
    const bool known = !o.intrinsics.empty();
    fp += fmt::format("camera {} single {} known {}\n", known ? "PINHOLE" : o.camera_model,
                      o.single_camera, join(o.intrinsics));
    redo = steps.run("feature extraction", fp, redo,
                     [&] { extract(known ? "PINHOLE" : o.camera_model, o.intrinsics); });
    fp += matcher_fp;
    redo = steps.run("matching", fp, redo, match);
    redo = steps.run("mapping", fp, redo, [&] {
      fs::remove_all(raw);
      fs::create_directories(raw);
      std::vector<std::string> args = {"--database_path", db.string(),     "--image_path",
                                       images.string(),   "--output_path", raw.string()};
      if (known) args.insert(args.end(), fixed_intrinsics.begin(), fixed_intrinsics.end());
      if (o.threads) args.insert(args.end(), {"--Mapper.num_threads", std::to_string(o.threads)});
      o.colmap.run("mapping", "mapper", args);
    });
  }

  SfmResult r;
  r.views = names.size();
  const auto [kept, model] = largest_model(raw, &r.models);
  if (kept < 0)
    throw ColmapError("mapping made no model: no two views could be matched; log " +
                      o.colmap.log_file.string());
  r.kept_model = kept;
  r.registered = model.images.size();
  std::set<std::string> in_model;
  for (const auto& [id, image] : model.images) in_model.insert(image.name);
  for (const std::string& n : names)
    if (!in_model.count(n)) r.unregistered.push_back(n);
  spdlog::info("{} of {} views registered ({} model{}; kept model {})", r.registered, r.views,
               r.models, r.models == 1 ? "" : "s", kept);
  if (!r.unregistered.empty()) spdlog::warn("not registered: {}", fmt::join(r.unregistered, ", "));
  const double share = double(r.registered) / double(r.views);
  // An imported model is the user's choice: fewer views is a warning only.
  if (imported && r.registered >= 2 && share < o.min_registered_fraction)
    spdlog::warn("the imported model holds {} of the {} images in {}", r.registered, r.views,
                 images.string());
  else if (r.registered < 2 || share < o.min_registered_fraction)
    throw ColmapError(
        fmt::format("only {} of {} views registered (minimum {:.0f}%); try "
                    "--matcher exhaustive, more overlapping photos, or known "
                    "intrinsics",
                    r.registered, r.views, 100 * o.min_registered_fraction));

  // Undistortion into PINHOLE, and the scene layout the trainer reads.
  r.scene = out / "scene";
  const fs::path sparse = r.scene / "sparse" / "0";
  // "layout 2": the scene has photo_cameras/ (outputs of older versions lack it).
  fp += fmt::format("kept {}\nlayout 2\n", kept);
  const bool undistort = !is_pinhole(model);
  steps.run("undistortion", fp, redo, [&] {
    fs::remove_all(r.scene);
    fs::create_directories(sparse);
    if (!undistort) {
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
    write_colmap_model(cameras_only(model), r.scene / kPhotoCamerasDir, ColmapFormat::kBinary);
  });
  if (undistort) undistort_user_id_maps(scene_dir, r.scene, model, o);
  link_user_files(scene_dir, r.scene, o.images_dir, undistort);
  // Said here, where the user's folder is named, rather than only by the
  // later stages, which see the output scene.
  if (!fs::exists(scene_dir / "sam2"))
    spdlog::warn("{}: no sam2/ folder of ID maps; op2gs-vote and op2gs-learn need it",
                 scene_dir.string());

  json accuracy = nullptr;
  if (!o.truth.empty()) {
    const ColmapModel truth = read_colmap_model(o.truth);
    std::set<std::string> true_names;
    for (const auto& [id, image] : truth.images) true_names.insert(image.name);
    if (std::count_if(in_model.begin(), in_model.end(),
                      [&](const std::string& n) { return true_names.count(n) > 0; }) < 3)
      throw InputError(o.truth, "the true model shares fewer than 3 image names with the scene");
    const PoseAccuracy acc = pose_accuracy(model, truth);
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
                        {"llff", o.llff},
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
