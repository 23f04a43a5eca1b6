// The SfM controller: one class whose run() is the sequence of named steps,
// each a short method (COLMAP's command lines, the photo checks, the scene
// folder and the resumable-step markers are in files of their own). It is
// about 400 lines because it has that many steps, not because a step is
// long.
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
#include "splat/dataset_layout.h"
#include "splat/error.h"
#include "splat/image.h"
#include "splat/photo_cameras.h"
#include "splat/sfm/alignment.h"
#include "splat/sfm/colmap_arguments.h"
#include "splat/sfm/colmap_database.h"
#include "splat/sfm/llff.h"
#include "splat/sfm/photo_checks.h"
#include "splat/sfm/resumable_steps.h"
#include "splat/sfm/scene_folder.h"
#include "splat/sfm/transforms_json.h"

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
  if (max_image_size < 100)
    throw std::invalid_argument("the maximum image size for SIFT must be >= 100 pixels");
  // Each is replaced inside <out>/scene/: a plain folder name, never a path.
  for (const std::string& dir : id_map_dirs)
    if (dir.empty() || dir == "." || dir == ".." || dir.find('/') != std::string::npos ||
        dir == images_dir || dir == "sparse")
      throw std::invalid_argument(
          fmt::format("--id-map-dirs: '{}' is not a folder name of the scene", dir));
}

namespace {

// colmap_has_cuda: what ColmapCommand::available found.
bool want_gpu(const SfmOptions& o, bool colmap_has_cuda) {
  if (o.gpu != SfmOptions::Gpu::kAuto) return o.gpu == SfmOptions::Gpu::kOn;
  return colmap_has_cuda && fs::exists("/dev/nvidia0");
}

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

// One SfM run in named steps, as COLMAP's AutomaticReconstructionController
// orders its own: import, or feature extraction, matching and mapping (or
// triangulation for known poses); then the largest model is kept,
// undistorted into the scene the trainer reads, and summarised. The steps
// share this context; each that runs COLMAP is skipped on a rerun with the
// same fingerprint (ResumableSteps), and any that runs makes the later ones
// run. Building COLMAP's command lines (colmap_arguments.h), checking the
// photos (photo_checks.h) and assembling the scene folder (scene_folder.h)
// are each in a file of their own.
class SfmController {
 public:
  SfmController(const fs::path& scene_dir, const fs::path& out, const SfmOptions& options)
      : user_(scene_dir), out_(out), o_(options), steps_(out) {
    o_.Check();
    fs::create_directories(out_);
    remove_abandoned_temporaries(out_);
    o_.colmap.log_file = out_ / "colmap.log";
    images_ = user_ / o_.images_dir;
    names_ = photo_names(images_);
    check_photos();
    if (is_transforms_json(o_.import_model))
      read_capture();
    else if (!o_.import_model.empty())
      imported_ = read_imported_model(o_.import_model, images_);
    fp_ = fmt::format("images {}\nin {}\nmax image size {}\n", fmt::join(names_, "\n"),
                      images_.string(), o_.max_image_size);
  }

  SfmResult run() {
    check_colmap();
    if (imported_ && triangulate_)
      run_known_poses(*imported_, "import " + fs::absolute(o_.import_model).string());
    else if (imported_)
      run_import();
    else if (o_.llff)
      run_llff();
    else
      run_sfm_steps();
    const ColmapModel model = keep_largest_model();
    run_undistortion(model);
    score_poses(model);
    write_summary(model);
    return r_;
  }

 private:
  // Photos stored turned are refused (photo_checks.h); photos of several
  // sizes (portrait and landscape mixed) cannot share one camera; COLMAP
  // reads 8-bit copies of 16-bit photos.
  void check_photos() {
    const PhotoHeaders headers = check_photo_headers(images_, names_);
    if (headers.sizes > 1 && o_.single_camera && o_.intrinsics.empty() && o_.import_model.empty() &&
        !o_.llff) {
      spdlog::warn(
          "the photos have {} different sizes (portrait and landscape mixed?): one "
          "camera per photo instead of one shared camera",
          headers.sizes);
      o_.single_camera = false;
    }
    if (!headers.deeper_than_8_bits) return;
    const fs::path copies = out_ / "images_8bit";
    const size_t made = make_eight_bit_copies(images_, names_, copies);
    spdlog::info("16-bit photos: COLMAP reads 8-bit copies in {} ({} made)", copies.string(), made);
    images_ = copies;
  }

  static bool is_transforms_json(const fs::path& p) {
    return p.extension() == ".json" && fs::is_regular_file(p);
  }

  // A nerfstudio / instant-ngp capture: its poses are kept; its points too,
  // if it has them, else COLMAP triangulates them for the poses.
  void read_capture() {
    TransformsCapture c = read_transforms_json(o_.import_model, images_);
    if (!c.missing.empty())
      spdlog::warn("{}: {} frame{} listed without a photo, skipped: {}", o_.import_model.string(),
                   c.missing.size(), c.missing.size() == 1 ? "" : "s", fmt::join(c.missing, ", "));
    spdlog::info("{} capture: {} frames, {} camera{}, {}", c.flavour, c.model.images.size(),
                 c.model.cameras.size(), c.model.cameras.size() == 1 ? "" : "s",
                 c.has_points ? fmt::format("{} points from {}", c.model.points3d.size(),
                                            c.points_file.filename().string())
                              : std::string("no points (COLMAP triangulates them)"));
    if (c.applied_transform)
      spdlog::info("applied_transform: kept, as nerfstudio applied it to the poses and the points");
    triangulate_ = !c.has_points;
    missing_ = c.missing;
    imported_ = std::move(c.model);
  }

  void check_colmap() {
    const bool needs_colmap = !imported_ || !is_pinhole(*imported_) || triangulate_;
    bool cuda = false;
    if (needs_colmap && !o_.colmap.available(&cuda))
      throw ColmapError(
          fmt::format("`{}` does not run: install COLMAP with `apt-get install "
                      "colmap` (scripts/setup.sh does), or give its path with --colmap",
                      o_.colmap.binary));
    gpu_ = want_gpu(o_, cuda);
  }

  void run_import() {
    fs::remove_all(raw());
    write_colmap_model(*imported_, raw() / "0", ColmapFormat::kBinary);
    fp_ += "import " + fs::absolute(o_.import_model).string();
    redo_ = true;
  }

  // 3DOVS's poses_bounds.npy: known poses.
  void run_llff() {
    const ImageInfo first = read_image_info(images_ / names_.front());
    run_known_poses(llff_to_colmap(user_ / "poses_bounds.npy", names_, first.width, first.height),
                    "llff");
  }

  // Known poses (LLFF, or a capture without points): features and matches of
  // the posed photos, then COLMAP triangulates the points with the cameras
  // held fixed.
  void run_known_poses(const ColmapModel& known, const std::string& source) {
    fp_ += fmt::format("{}\n{}", source, model_fingerprint(known));
    const ColmapCamera& camera = known.cameras.begin()->second;
    const bool shared = known.cameras.size() == 1;
    const std::string model = camera_model_by_id(camera.model_id)->name;
    std::vector<std::string> posed;
    for (const auto& [id, image] : known.images) posed.push_back(image.name);
    step("feature extraction", [&] {
      run_feature_extraction(model, shared ? camera.params : std::vector<double>{}, shared, posed);
    });
    fp_ += matcher_fingerprint();
    step("matching", [&] { run_matching(); });
    step("triangulation", [&] { run_triangulation(known); });
  }

  // The cameras and poses of a model, as text: a changed pose reruns the steps.
  static std::string model_fingerprint(const ColmapModel& m) {
    std::string f;
    for (const auto& [id, c] : m.cameras)
      f += fmt::format("camera {} {} {}x{} {}\n", id, c.model_id, c.width, c.height,
                       colmap_list(c.params));
    for (const auto& [id, i] : m.images)
      f += fmt::format("image {} {} {:.12g} {:.12g}\n", i.name, i.camera_id,
                       fmt::join(i.qvec.data(), i.qvec.data() + 4, " "),
                       fmt::join(i.tvec.data(), i.tvec.data() + 3, " "));
    return f;
  }

  void run_sfm_steps() {
    const bool known = !o_.intrinsics.empty();
    fp_ += fmt::format("camera {} single {} known {}\n", known ? "PINHOLE" : o_.camera_model,
                       o_.single_camera, colmap_list(o_.intrinsics));
    step("feature extraction", [&] {
      run_feature_extraction(known ? "PINHOLE" : o_.camera_model, o_.intrinsics,
                             o_.single_camera || known, {});
    });
    fp_ += matcher_fingerprint();
    step("matching", [&] { run_matching(); });
    step("mapping", [&] { run_mapping(known); });
  }

  // SIFT features of `only` (every photo if empty), with one shared camera
  // or one per photo; `params` fixes the shared camera's intrinsics.
  void run_feature_extraction(const std::string& model, const std::vector<double>& params,
                              bool single_camera, const std::vector<std::string>& only) {
    fs::remove(database());
    FeatureExtraction e{database(), images_,           model,     params, single_camera, {},
                        gpu_,       o_.max_image_size, o_.threads};
    if (!only.empty()) {
      e.image_list = out_ / "image_list.txt";
      write_text_atomically(e.image_list, fmt::format("{}\n", fmt::join(only, "\n")));
    }
    o_.colmap.run("feature extraction", "feature_extractor", feature_extractor_arguments(e));
    const size_t read = read_database_images(database()).size();
    const size_t wanted = only.empty() ? names_.size() : only.size();
    if (read < wanted)
      throw ColmapError(
          fmt::format("COLMAP could read only {} of the {} photos in {} (a format "
                      "it does not read?); log {}",
                      read, wanted, images_.string(), o_.colmap.log_file.string()));
  }

  bool sequential() const {
    return o_.matcher == SfmMatcher::kSequential ||
           (o_.matcher == SfmMatcher::kAuto && names_.size() > 250);
  }

  std::string matcher_fingerprint() const {
    return fmt::format("matcher {} overlap {} vocab {}\n",
                       sequential() ? "sequential" : "exhaustive", o_.sequential_overlap,
                       o_.vocab_tree.string());
  }

  void run_matching() {
    const Matching m{database(), sequential(), o_.sequential_overlap, o_.vocab_tree, gpu_};
    o_.colmap.run("matching", matcher_command(m), matcher_arguments(m));
  }

  void run_triangulation(const ColmapModel& known) {
    // COLMAP aborts on an empty bundle adjustment: say why instead.
    if (count_verified_matches(database()) == 0)
      throw ColmapError(fmt::format(
          "matching found no feature matches between the {} posed photos, so no points can be "
          "triangulated: the photos are too small or overlap too little (give points with the "
          "capture, e.g. nerfstudio's sparse_pc.ply); log {}",
          known.images.size(), o_.colmap.log_file.string()));
    fs::remove_all(raw());
    fs::create_directories(raw() / "0");
    write_colmap_model(with_database_ids(known, database()), out_ / "llff_model",
                       ColmapFormat::kText);
    o_.colmap.run(
        "triangulation", "point_triangulator",
        point_triangulator_arguments(database(), images_, out_ / "llff_model", raw() / "0"));
  }

  void run_mapping(bool known_intrinsics) {
    fs::remove_all(raw());
    fs::create_directories(raw());
    o_.colmap.run("mapping", "mapper",
                  mapper_arguments(database(), images_, raw(), known_intrinsics, o_.threads));
  }

  // The model with the most registered views; fails when too few registered.
  ColmapModel keep_largest_model() {
    r_.views = names_.size();
    auto [kept, model] = largest_model(raw(), &r_.models);
    if (kept < 0)
      throw ColmapError("mapping made no model: no two views could be matched; log " +
                        o_.colmap.log_file.string());
    r_.kept_model = kept;
    r_.registered = model.images.size();
    std::set<std::string> registered;
    for (const auto& [id, image] : model.images) registered.insert(image.name);
    for (const std::string& n : names_)
      if (!registered.count(n)) r_.unregistered.push_back(n);
    spdlog::info("{} of {} views registered ({} model{}; kept model {})", r_.registered, r_.views,
                 r_.models, r_.models == 1 ? "" : "s", kept);
    if (!r_.unregistered.empty())
      spdlog::warn("not registered: {}", fmt::join(r_.unregistered, ", "));
    const double share = double(r_.registered) / double(r_.views);
    // An imported model is the user's choice: fewer views is a warning only.
    if (imported_ && r_.registered >= 2 && share < o_.min_registered_fraction)
      spdlog::warn("the imported model holds {} of the {} images in {}", r_.registered, r_.views,
                   images_.string());
    else if (r_.registered < 2 || share < o_.min_registered_fraction)
      throw ColmapError(
          fmt::format("only {} of {} views registered (minimum {:.0f}%); try "
                      "--matcher exhaustive, more overlapping photos, or known "
                      "intrinsics",
                      r_.registered, r_.views, 100 * o_.min_registered_fraction));
    return std::move(model);
  }

  // Undistortion into PINHOLE, and the scene layout the trainer reads.
  void run_undistortion(const ColmapModel& model) {
    r_.scene = out_ / "scene";
    const fs::path sparse = r_.scene / "sparse" / "0";
    // "layout 2": the scene has photo_cameras/ (outputs of older versions lack it).
    fp_ += fmt::format("kept {}\nlayout 2\n", r_.kept_model);
    const bool undistort = !is_pinhole(model);
    step("undistortion", [&] {
      fs::remove_all(r_.scene);
      fs::create_directories(sparse);
      if (!undistort) return write_pinhole_scene(model, images_, r_.scene);
      const fs::path und = out_ / "undistorted";
      fs::remove_all(und);
      o_.colmap.run(
          "undistortion", "image_undistorter",
          image_undistorter_arguments(images_, raw() / std::to_string(r_.kept_model), und));
      write_undistorted_scene(und, model, r_.scene);
    });
    if (undistort) undistort_user_id_maps(user_, r_.scene, model, o_.id_map_dirs);
    link_user_files(user_, r_.scene, o_.images_dir, undistort);
    spdlog::info("scene folder: {}", layout_description(detect_dataset_layout(user_)));
    // Said here, where the user's folder is named, rather than only by the
    // later stages, which see the output scene.
    try {
      resolve_id_map_folder(user_, "auto");
    } catch (const InputError& e) {
      spdlog::warn("{}; op2gs-vote and op2gs-learn need one", e.what());
    }
  }

  // Against the true cameras, if given (after a similarity alignment).
  void score_poses(const ColmapModel& model) {
    if (o_.truth.empty()) return;
    const PoseAccuracy acc = pose_accuracy_against(model, o_.truth);
    r_.center_rmse = acc.center_rmse;
    r_.rotation_error_deg = acc.rotation_error_deg;
    accuracy_ = {{"matched", acc.matched},
                 {"center_rmse", acc.center_rmse},
                 {"rotation_error_deg", acc.rotation_error_deg},
                 {"scale", acc.alignment.scale}};
    spdlog::info("against the true cameras: centre RMSE {:.5f}, rotation error {:.3f} deg",
                 acc.center_rmse, acc.rotation_error_deg);
  }

  void write_summary(const ColmapModel& model) const {
    const json summary = {{"pose_accuracy", accuracy_},
                          {"llff", o_.llff},
                          {"views", r_.views},
                          {"registered", r_.registered},
                          {"unregistered", r_.unregistered},
                          {"models", r_.models},
                          {"kept_model", r_.kept_model},
                          {"points", model.points3d.size()},
                          {"gpu", gpu_},
                          {"imported", o_.import_model.string()},
                          {"frames_without_photo", missing_}};
    write_text_atomically(out_ / "sfm.json", summary.dump(2) + "\n");
  }

  // Runs a step unless it finished before with the fingerprint so far.
  void step(const std::string& name, const std::function<void()>& body) {
    redo_ = steps_.run(name, fp_, redo_, body);
  }
  fs::path database() const { return out_ / "database.db"; }
  fs::path raw() const { return out_ / "sparse_raw"; }

  const fs::path user_, out_;
  SfmOptions o_;
  ResumableSteps steps_;
  fs::path images_;
  std::vector<std::string> names_;
  std::optional<ColmapModel> imported_;
  bool gpu_ = false;
  bool triangulate_ = false;          // the imported capture has poses but no points
  std::vector<std::string> missing_;  // frames of a capture without their photo
  std::string fp_;                    // fingerprint of the inputs and options of the steps so far
  bool redo_ = false;                 // a step ran, so every later one must run too
  json accuracy_ = nullptr;
  SfmResult r_;
};

}  // namespace

SfmResult run_sfm(const fs::path& scene_dir, const fs::path& out, const SfmOptions& options) {
  return SfmController(scene_dir, out, options).run();
}

}  // namespace splat
