// op2gs-synth: generates a synthetic benchmark scene (LERF-Mask layout, and
// optionally 3DOVS) with exact and SAM2-like corrupted instance maps.

#include "eval/synthetic/generator.h"
#include "stages/common.h"

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
  app.add_option("--sam2-strength", o.sam2.strength, "scales every SAM2 corruption (0 = exact)")
      ->capture_default_str();
  app.add_option("--sam2-jitter", o.sam2.boundary_jitter_px, "boundary jitter amplitude in pixels")
      ->capture_default_str();
  app.add_option("--sam2-miss", o.sam2.miss_probability,
                 "chance per object and view of a missed part")
      ->capture_default_str();
  app.add_option("--sam2-leak", o.sam2.leak_probability,
                 "chance per object and view of a leak onto a neighbour")
      ->capture_default_str();
  app.add_option("--sam2-blobs", o.sam2.spurious_blobs, "mean spurious blobs per view")
      ->capture_default_str();
  app.add_option("--sam2-persistence", o.sam2.persistence_views,
                 "mean run of consecutive views over which a miss or leak persists "
                 "(1: independent per view)")
      ->capture_default_str();
  std::string shipping = "op2gs";
  app.add_option("--as", shipping,
                 "ship the scene as: op2gs (its own layout), lerf-mask-download (Gaussian "
                 "Grouping's LERF-Mask download), nerfstudio or instant-ngp (transforms.json)")
      ->capture_default_str();
  app.add_option("--distortion", o.distortion,
                 "render the photos through an OPENCV lens k1 k2 p1 p2")
      ->expected(4);
  app.add_flag("--3dovs-prepared", o.ovs_prepared,
               "write the 3DOVS layout as ObjectGS prepares it (sparse/0/, object_mask_deva/)");
  app.add_flag("--force", force, "replace an existing output folder");
  return stages::run_stage(app, argc, argv, [&] {
    o.write_sparse = !no_sparse;
    using synth::Shipping;
    o.shipping =
        stages::parse_choice<Shipping>("--as", shipping,
                                       {{"op2gs", Shipping::kOp2gs},
                                        {"lerf-mask-download", Shipping::kLerfMaskDownload},
                                        {"nerfstudio", Shipping::kNerfstudio},
                                        {"instant-ngp", Shipping::kInstantNgp}});
    synth::generate_scene(o, out, force);
    spdlog::info("scene written to {}", out);
  });
}
