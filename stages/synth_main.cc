// op2gs-synth: generates a synthetic benchmark scene (LERF-Mask layout, and
// optionally 3DOVS) with exact and SAM2-like corrupted instance maps.

#include "stages/common.h"
#include "stages/mask_error_options.h"
#include "synth/generator.h"

int main(int argc, char** argv) {
  CLI::App app{"Generate a ray-traced synthetic scene in the LERF-Mask layout."};
  synth::SynthOptions o;
  std::string out;
  bool force = false, no_sparse = false;
  app.add_option("output", out, "scene folder to create")->required();
  app.add_option("--views", o.views, "number of views on the orbit")->capture_default_str();
  app.add_option("--width", o.width, "image width in pixels")->capture_default_str();
  app.add_option("--height", o.height, "image height in pixels")->capture_default_str();
  app.add_option("--seed", o.seed, "random seed (cameras, textures, SAM2 corruption)")
      ->capture_default_str();
  app.add_option("--supersample", o.supersample, "samples per pixel along each axis")
      ->capture_default_str();
  app.add_option("--test-every", o.test_every, "view i is a test view when i % N == 0")
      ->capture_default_str();
  app.add_option("--fov", o.fov_x_degrees, "horizontal field of view in degrees")
      ->capture_default_str();
  app.add_option("--orbit-radius", o.orbit_radius, "camera distance from the scene centre")
      ->capture_default_str();
  app.add_option("--orbit-height", o.orbit_height, "camera height above the ground")
      ->capture_default_str();
  app.add_option("--points", o.num_points, "sparse points to sample on surfaces")
      ->capture_default_str();
  app.add_flag("--no-sparse", no_sparse, "write no sparse/ model (to test SfM from scratch)");
  app.add_option("--3dovs", o.ovs_dir, "also write the scene in the 3DOVS layout to this folder");
  stages::add_mask_error_options(app, o.sam2, "sam2-");
  std::string format = "op2gs";
  app.add_option("--as", format,
                 "ship the scene as: op2gs (its own layout), lerf-mask-download (Gaussian "
                 "Grouping's LERF-Mask download), nerfstudio or instant-ngp (transforms.json)")
      ->capture_default_str();
  app.add_option("--distortion", o.distortion,
                 "render the photos through an OPENCV lens k1 k2 p1 p2")
      ->expected(4);
  app.add_flag("--3dovs-prepared", o.ovs_prepared,
               "write the 3DOVS layout as ObjectGS prepares it (sparse/0/, object_mask_deva/)");
  app.add_flag("--force", force, "replace an existing output folder");

  // Real-capture imperfections (docs/synthetic.md): --capture sets all of
  // them at typical strengths; each option alone overrides its value.
  bool capture = false;
  app.add_flag("--capture", capture,
               "a real capture's imperfections at typical strengths: exposure and white-balance "
               "drift, noise, JPEG, gloss, SfM-like pose error, ID switches, merges, late objects");
  synth::CaptureOptions c;
  synth::TrackErrorOptions t;
  const auto* exposure = app.add_option("--exposure", c.exposure_stops,
                                        "standard deviation of the views' exposure, in stops");
  const auto* balance = app.add_option("--white-balance", c.white_balance,
                                       "standard deviation of the per-channel gain (log)");
  const auto* noise = app.add_option("--noise", c.noise, "sensor noise (read noise, 0..1 scale)");
  const auto* jpeg = app.add_option("--jpeg-quality", c.jpeg_quality,
                                    "pass the photos through JPEG at this quality (0: off)");
  const auto* specular =
      app.add_option("--specular", c.specular, "strength of the objects' specular highlights");
  std::vector<double> pose;
  const auto* pose_error = app.add_option("--pose-error", pose,
                                          "camera-file error: rotation (degrees) and centre "
                                          "(fraction of the orbit radius), standard deviations")
                               ->expected(2);
  const auto* focal =
      app.add_option("--focal-error", c.focal_error, "relative error of the camera files' focal");
  const auto* switches =
      app.add_option("--id-switches", t.id_switches, "expected ID switches per object");
  const auto* merges =
      app.add_option("--merges", t.merges, "expected merges per pair of touching objects");
  const auto* late =
      app.add_option("--late-objects", t.late_objects, "share of objects first tracked late");
  return stages::run_stage(app, argc, argv, [&] {
    if (capture) {
      o.capture = synth::CaptureOptions::typical();
      o.tracks = synth::TrackErrorOptions::typical();
    }
    const auto given = [](const CLI::Option* option) { return option->count() > 0; };
    if (given(exposure)) o.capture.exposure_stops = c.exposure_stops;
    if (given(balance)) o.capture.white_balance = c.white_balance;
    if (given(noise)) o.capture.noise = c.noise;
    if (given(jpeg)) o.capture.jpeg_quality = c.jpeg_quality;
    if (given(specular)) o.capture.specular = c.specular;
    if (given(pose_error)) {
      o.capture.pose_rotation_degrees = pose[0];
      o.capture.pose_translation = pose[1];
    }
    if (given(focal)) o.capture.focal_error = c.focal_error;
    if (given(switches)) o.tracks.id_switches = t.id_switches;
    if (given(merges)) o.tracks.merges = t.merges;
    if (given(late)) o.tracks.late_objects = t.late_objects;
    o.write_sparse = !no_sparse;
    using synth::OutputFormat;
    o.format =
        stages::parse_choice<OutputFormat>("--as", format,
                                           {{"op2gs", OutputFormat::kOp2gs},
                                            {"lerf-mask-download", OutputFormat::kLerfMaskDownload},
                                            {"nerfstudio", OutputFormat::kNerfstudio},
                                            {"instant-ngp", OutputFormat::kInstantNgp}});
    synth::generate_scene(o, out, force);
    spdlog::info("scene written to {}", out);
  });
}
