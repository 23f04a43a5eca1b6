// op2gs-sfm: camera poses and sparse points for a scene of photos with
// COLMAP, undistorted to the pinhole model the trainer reads; or the import
// of an existing COLMAP model.

#include "splat/sfm/sfm_run.h"
#include "stages/common.h"

int main(int argc, char** argv) {
  CLI::App app{"Structure from motion with COLMAP: from photos to an undistorted pinhole model."};
  splat::SfmOptions o;
  std::string scene, out, matcher = "auto", gpu = "auto", vocab, import_model;
  app.add_option("scene", scene, "scene folder with images/ (never modified)")->required();
  app.add_option("out", out, "output folder; the trainer's scene is <out>/scene")->required();
  app.add_option("--images", o.images_dir, "image folder inside the scene")->capture_default_str();
  app.add_option("--matcher", matcher,
                 "exhaustive, sequential (video-like sets), or auto (exhaustive up to 250 images)")
      ->capture_default_str();
  app.add_option("--overlap", o.sequential_overlap, "sequential matching: neighbours per image")
      ->capture_default_str();
  app.add_option("--vocab-tree", vocab, "vocabulary tree file: loop detection in sequential mode");
  app.add_option("--camera-model", o.camera_model,
                 "COLMAP camera model (PINHOLE, SIMPLE_RADIAL, OPENCV, ...)")
      ->capture_default_str();
  app.add_option("--single-camera", o.single_camera, "one camera shared by all images (1 or 0)")
      ->capture_default_str();
  app.add_option("--intrinsics", o.intrinsics, "known fx fy cx cy (PINHOLE, held fixed)")
      ->expected(4);
  app.add_option("--gpu", gpu, "COLMAP's GPU SIFT: auto, on, off")->capture_default_str();
  app.add_option("--min-registered", o.min_registered_fraction,
                 "fail when fewer than this share of the views register")
      ->capture_default_str();
  app.add_option("--threads", o.threads, "COLMAP threads (0: all cores)")->capture_default_str();
  app.add_option("--max-image-size", o.max_image_size,
                 "SIFT on photos scaled to at most this many pixels on their long side "
                 "(phone photos: faster; 1080p frames stay whole)")
      ->capture_default_str();
  app.add_option("--id-map-dirs", o.id_map_dirs,
                 "ID map folders in the scene, resampled with the images when they are undistorted")
      ->capture_default_str();
  app.add_option("--colmap", o.colmap.binary, "the colmap binary")->capture_default_str();
  app.add_option("--import", import_model,
                 "import this COLMAP model folder (binary or text), or a nerfstudio / instant-ngp "
                 "transforms.json, instead of running SfM");
  std::string truth;
  app.add_flag("--llff", o.llff,
               "use the cameras of <scene>/poses_bounds.npy (3DOVS); only triangulate points");
  app.add_option("--truth", truth,
                 "true cameras (COLMAP model): report the pose accuracy after alignment");
  return stages::run_stage(app, argc, argv, [&] {
    o.matcher =
        stages::parse_choice<splat::SfmMatcher>("--matcher", matcher,
                                                {{"auto", splat::SfmMatcher::kAuto},
                                                 {"exhaustive", splat::SfmMatcher::kExhaustive},
                                                 {"sequential", splat::SfmMatcher::kSequential}});
    using Gpu = splat::SfmOptions::Gpu;
    o.gpu = stages::parse_choice<Gpu>("--gpu", gpu,
                                      {{"auto", Gpu::kAuto}, {"on", Gpu::kOn}, {"off", Gpu::kOff}});
    o.vocab_tree = vocab;
    o.import_model = import_model;
    o.truth = truth;
    try {
      const splat::SfmResult r = splat::run_sfm(scene, out, o);
      spdlog::info("{} of {} views registered; the trainer's scene is {}", r.registered, r.views,
                   r.scene.string());
    } catch (const splat::ColmapError& e) {
      throw std::runtime_error(e.what());
    }
  });
}
