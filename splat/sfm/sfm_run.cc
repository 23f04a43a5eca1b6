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
#include "splat/sfm/colmap_database.h"
#include "splat/sfm/llff.h"
#include "splat/sfm/transforms_json.h"
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
  // distorted/ and stereo/ are COLMAP's leftovers in the LERF-Mask download.
  std::set<std::string> own = {images, "sparse", "distorted", "stereo"};
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

// One SfM run in named steps, as COLMAP's AutomaticReconstructionController
// orders its own: import, or feature extraction, matching and mapping (or
// triangulation for known poses); then the largest model is kept,
// undistorted into the scene the trainer reads, and summarised. The steps
// share this context; each that runs COLMAP is skipped on a rerun with the
// same fingerprint (Steps), and any that runs makes the later ones run.
class SfmController {
 public:
  SfmController(const fs::path& scene_dir, const fs::path& out, const SfmOptions& options)
      : user_(scene_dir), out_(out), o_(options), steps_(out) {
    o_.Check();
    fs::create_directories(out_);
    remove_abandoned_temporaries(out_);
    o_.colmap.log_file = out_ / "colmap.log";
    images_ = user_ / o_.images_dir;
    names_ = image_names(images_);
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
  // Every photo's header: EXIF-rotated photos are refused (COLMAP, SAM2 and
  // the trainer would not agree on which way is up); photos of several sizes
  // (portrait and landscape mixed) cannot share one camera.
  void check_photos() {
    std::set<std::pair<int, int>> sizes;
    bool deep = false;
    for (const std::string& name : names_) {
      const ImageInfo info = read_image_info(images_ / name);
      deep |= info.bits > 8;
      if (info.orientation != 1)
        throw InputError(images_ / name,
                         fmt::format("EXIF orientation {} (the photo is stored turned or "
                                     "mirrored): store the photos upright first, e.g. `exiftran "
                                     "-ai *.jpg` or `mogrify -auto-orient *.jpg`, and make the ID "
                                     "maps from the upright photos",
                                     info.orientation));
      sizes.insert({info.width, info.height});
    }
    if (sizes.size() > 1 && o_.single_camera && o_.intrinsics.empty() && o_.import_model.empty() &&
        !o_.llff) {
      spdlog::warn(
          "the photos have {} different sizes (portrait and landscape mixed?): one "
          "camera per photo instead of one shared camera",
          sizes.size());
      o_.single_camera = false;
    }
    if (deep) use_eight_bit_copies();
  }

  // COLMAP 3.8 cannot read 16-bit PNGs: it gets 8-bit copies (the views the
  // trainer reads are 8-bit too once COLMAP undistorts them, as 3DGS's are).
  // Copies are remade only when a photo is newer.
  void use_eight_bit_copies() {
    const fs::path copies = out_ / "images_8bit";
    fs::create_directories(copies);
    size_t made = 0;
    for (const std::string& name : names_) {
      const fs::path from = images_ / name, to = copies / name;
      if (fs::exists(to) && fs::last_write_time(to) >= fs::last_write_time(from)) continue;
      write_image_rgb(to, read_image_rgb(from));
      ++made;
    }
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
      f +=
          fmt::format("camera {} {} {}x{} {}\n", id, c.model_id, c.width, c.height, join(c.params));
    for (const auto& [id, i] : m.images)
      f += fmt::format("image {} {} {:.12g} {:.12g}\n", i.name, i.camera_id,
                       fmt::join(i.qvec.data(), i.qvec.data() + 4, " "),
                       fmt::join(i.tvec.data(), i.tvec.data() + 3, " "));
    return f;
  }

  void run_sfm_steps() {
    const bool known = !o_.intrinsics.empty();
    fp_ += fmt::format("camera {} single {} known {}\n", known ? "PINHOLE" : o_.camera_model,
                       o_.single_camera, join(o_.intrinsics));
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
    std::vector<std::string> args = {"--database_path",
                                     database().string(),
                                     "--image_path",
                                     images_.string(),
                                     "--ImageReader.single_camera",
                                     single_camera ? "1" : "0",
                                     "--ImageReader.camera_model",
                                     model,
                                     "--SiftExtraction.use_gpu",
                                     gpu_ ? "1" : "0",
                                     "--SiftExtraction.max_image_size",
                                     std::to_string(o_.max_image_size)};
    if (!params.empty()) args.insert(args.end(), {"--ImageReader.camera_params", join(params)});
    if (!only.empty()) {
      const fs::path list = out_ / "image_list.txt";
      write_text_atomically(list, fmt::format("{}\n", fmt::join(only, "\n")));
      args.insert(args.end(), {"--image_list_path", list.string()});
    }
    if (o_.threads)
      args.insert(args.end(), {"--SiftExtraction.num_threads", std::to_string(o_.threads)});
    o_.colmap.run("feature extraction", "feature_extractor", args);
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
    std::vector<std::string> args = {"--database_path", database().string(),
                                     "--SiftMatching.use_gpu", gpu_ ? "1" : "0"};
    if (sequential()) {
      args.insert(args.end(),
                  {"--SequentialMatching.overlap", std::to_string(o_.sequential_overlap),
                   "--SequentialMatching.loop_detection", o_.vocab_tree.empty() ? "0" : "1"});
      if (!o_.vocab_tree.empty())
        args.insert(args.end(), {"--SequentialMatching.vocab_tree_path", o_.vocab_tree.string()});
    }
    o_.colmap.run("matching", sequential() ? "sequential_matcher" : "exhaustive_matcher", args);
  }

  // Bundle adjustment leaves known intrinsics as they are.
  static void add_fixed_intrinsics(std::vector<std::string>& args) {
    args.insert(args.end(),
                {"--Mapper.ba_refine_focal_length", "0", "--Mapper.ba_refine_principal_point", "0",
                 "--Mapper.ba_refine_extra_params", "0"});
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
    std::vector<std::string> args = {"--database_path", database().string(),
                                     "--image_path",    images_.string(),
                                     "--input_path",    (out_ / "llff_model").string(),
                                     "--output_path",   (raw() / "0").string()};
    add_fixed_intrinsics(args);
    o_.colmap.run("triangulation", "point_triangulator", args);
  }

  void run_mapping(bool known_intrinsics) {
    fs::remove_all(raw());
    fs::create_directories(raw());
    std::vector<std::string> args = {"--database_path", database().string(), "--image_path",
                                     images_.string(),  "--output_path",     raw().string()};
    if (known_intrinsics) add_fixed_intrinsics(args);
    if (o_.threads) args.insert(args.end(), {"--Mapper.num_threads", std::to_string(o_.threads)});
    o_.colmap.run("mapping", "mapper", args);
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
    for (const auto& [id, image] : model.images) registered_.insert(image.name);
    for (const std::string& n : names_)
      if (!registered_.count(n)) r_.unregistered.push_back(n);
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
      if (!undistort) {
        write_colmap_model(model, sparse, ColmapFormat::kBinary);
        relink(images_, r_.scene / "images");
        return;
      }
      const fs::path und = out_ / "undistorted";
      fs::remove_all(und);
      o_.colmap.run("undistortion", "image_undistorter",
                    {"--image_path", images_.string(), "--input_path",
                     (raw() / std::to_string(r_.kept_model)).string(), "--output_path",
                     und.string(), "--output_type", "COLMAP"});
      write_colmap_model(read_colmap_model(und / "sparse"), sparse, ColmapFormat::kBinary);
      relink(und / "images", r_.scene / "images");
      write_colmap_model(cameras_only(model), r_.scene / kPhotoCamerasDir, ColmapFormat::kBinary);
    });
    if (undistort) undistort_user_id_maps(user_, r_.scene, model, o_);
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
    const ColmapModel truth = read_colmap_model(o_.truth);
    std::set<std::string> true_names;
    for (const auto& [id, image] : truth.images) true_names.insert(image.name);
    if (std::count_if(registered_.begin(), registered_.end(),
                      [&](const std::string& n) { return true_names.count(n) > 0; }) < 3)
      throw InputError(o_.truth, "the true model shares fewer than 3 image names with the scene");
    const PoseAccuracy acc = pose_accuracy(model, truth);
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
  Steps steps_;
  fs::path images_;
  std::vector<std::string> names_;
  std::optional<ColmapModel> imported_;
  bool gpu_ = false;
  bool triangulate_ = false;          // the imported capture has poses but no points
  std::vector<std::string> missing_;  // frames of a capture without their photo
  std::string fp_;                    // fingerprint of the inputs and options of the steps so far
  bool redo_ = false;                 // a step ran, so every later one must run too
  std::set<std::string> registered_;
  json accuracy_ = nullptr;
  SfmResult r_;
};

}  // namespace

SfmResult run_sfm(const fs::path& scene_dir, const fs::path& out, const SfmOptions& options) {
  return SfmController(scene_dir, out, options).run();
}

}  // namespace splat
