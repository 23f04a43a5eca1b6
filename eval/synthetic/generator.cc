#include "eval/synthetic/generator.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <nlohmann/json.hpp>
#include <random>
#include <set>

#include "eval/synthetic/raytracer.h"
#include "splat/atomic_file.h"
#include "splat/camera_distortion.h"
#include "splat/id_maps.h"
#include "splat/image.h"
#include "splat/npy.h"

namespace synth {
namespace fs = std::filesystem;
using json = nlohmann::json;

void SynthOptions::Check() const {
  auto fail = [](const std::string& s) { throw std::invalid_argument(s); };
  if (views < 2) fail(fmt::format("views must be >= 2, not {}", views));
  if (width < 8 || height < 8) fail(fmt::format("image size {}x{} is too small", width, height));
  if (supersample < 1 || supersample > 8) fail("supersample must be in 1..8");
  if (test_every < 2) fail("test_every must be >= 2");
  if (!(fov_x_degrees > 5 && fov_x_degrees < 150)) fail("fov_x_degrees must be in (5, 150)");
  if (!(orbit_radius > 0.5)) fail("orbit_radius must be > 0.5");
  if (num_points < 0) fail("num_points must be >= 0");
  if (!ovs_dir.empty() && (ovs_test_views < 1 || ovs_test_views > views))
    fail("ovs_test_views must be in 1..views");
  if (!distortion.empty() && distortion.size() != 4)
    fail("distortion is four OPENCV coefficients: k1 k2 p1 p2");
  if (!distortion.empty() && shipping == Shipping::kLerfMaskDownload)
    fail("the LERF-Mask download holds undistorted photos: no distortion");
  if (ovs_prepared && ovs_dir.empty()) fail("a prepared 3DOVS layout needs its folder");
  sam2.Check();
  tracks.Check();
  capture.Check();
}

std::string view_name(int i, const std::string& extension) {
  return fmt::format("frame_{:05d}{}", i, extension);
}

namespace {

// The PINHOLE camera of a view.
splat::ColmapCamera model_camera(const splat::Camera& c) {
  return {1, 1, uint64_t(c.width), uint64_t(c.height), {c.fx, c.fy, c.cx, c.cy}};
}

}  // namespace

splat::ColmapCamera photo_camera(const SynthOptions& o, const splat::Camera& c) {
  splat::ColmapCamera camera = model_camera(c);
  if (!o.distortion.empty()) {
    camera.model_id = splat::camera_model_by_name("OPENCV")->id;
    camera.params.insert(camera.params.end(), o.distortion.begin(), o.distortion.end());
  }
  return camera;
}

std::vector<splat::Camera> orbit_cameras(const SynthOptions& o, const SceneLayout& layout) {
  std::mt19937_64 rng(o.seed * 7919 + 1);
  std::uniform_real_distribution<double> u(-1, 1);
  const double fx = 0.5 * o.width / std::tan(0.5 * o.fov_x_degrees * M_PI / 180.0);
  std::vector<splat::Camera> cams;
  for (int i = 0; i < o.views; ++i) {
    const double angle = 2 * M_PI * (i + 0.3 * u(rng)) / o.views;
    const double r = o.orbit_radius * (1 + o.radius_jitter * u(rng));
    const double h = o.orbit_height + o.height_jitter * u(rng);
    const Eigen::Vector3d eye =
        layout.look_at + Eigen::Vector3d(r * std::cos(angle), 0, r * std::sin(angle));
    const Eigen::Vector3d target =
        layout.look_at + 0.1 * Eigen::Vector3d(u(rng), 0.5 * u(rng), u(rng));
    cams.push_back(splat::Camera::look_at(Eigen::Vector3d(eye.x(), h, eye.z()), target,
                                          Eigen::Vector3d::UnitY(), o.width, o.height, fx, fx));
  }
  return cams;
}

namespace {

// Renders the photo of `cam`, through the lens of `distorted` when given.
void render_view(const RayTracer& tracer, const splat::Camera& cam, int supersample,
                 const splat::ColmapCamera* distorted, splat::ImageRGB& image, splat::IdMap& ids) {
  image = splat::ImageRGB(cam.width, cam.height);
  ids = splat::IdMap(cam.width, cam.height);
  const Eigen::Vector3d origin = cam.center();
  const splat::ColmapCamera pinhole = model_camera(cam);
  // The ray of a photo pixel position: the pinhole ray of where the lens maps it.
  const auto ray = [&](double x, double y) {
    if (!distorted) return cam.pixel_ray(x, y);
    const Eigen::Vector2d u = splat::undistorted_position(*distorted, pinhole, x, y);
    return cam.pixel_ray(u.x(), u.y());
  };
  tbb::parallel_for(0, cam.height, [&](int y) {
    for (int x = 0; x < cam.width; ++x) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int sy = 0; sy < supersample; ++sy)
        for (int sx = 0; sx < supersample; ++sx)
          sum +=
              tracer.trace(origin, ray(x + (sx + 0.5) / supersample, y + (sy + 0.5) / supersample));
      sum /= double(supersample * supersample);
      float* px = image.pixel(x, y);
      for (int c = 0; c < 3; ++c) px[c] = float(sum[c]);
      // Pixel centres at +0.5 (the convention of splat::Camera).
      ids.at(x, y) = uint16_t(tracer.instance_id(origin, ray(x + 0.5, y + 0.5)));
    }
  });
}

}  // namespace

splat::ColmapModel sample_sparse_model(const RayTracer& tracer,
                                       const std::vector<splat::Camera>& cameras,
                                       const std::vector<std::string>& names, int num_points,
                                       uint64_t seed, const splat::ColmapCamera* distorted) {
  struct Sample {
    bool valid = false;
    Eigen::Vector3d xyz;
    Eigen::Vector3d color;
    std::vector<std::pair<int, Eigen::Vector2d>> observations;  // view, pixel
  };
  std::vector<Sample> samples(num_points);
  tbb::parallel_for(0, num_points, [&](int i) {
    std::mt19937_64 rng(seed * 1000003 + i);
    std::uniform_real_distribution<double> u(0, 1);
    const splat::Camera& cam = cameras[i % cameras.size()];
    const Eigen::Vector3d dir = cam.pixel_ray(u(rng) * cam.width, u(rng) * cam.height);
    // SfM finds no stable points on semi-transparent surfaces.
    const Hit hit = tracer.intersect(cam.center(), dir, /*skip_transparent=*/true);
    Sample& s = samples[i];
    s.xyz = hit.point;
    s.color = tracer.surface_color(hit);
    for (size_t v = 0; v < cameras.size(); ++v) {
      const Eigen::Vector3d xc = cameras[v].world_to_camera(hit.point);
      if (xc.z() < 0.2) continue;
      const Eigen::Vector2d px = cameras[v].camera_to_pixel(xc);
      if (px.x() < 0 || px.y() < 0 || px.x() >= cameras[v].width || px.y() >= cameras[v].height)
        continue;
      const Eigen::Vector2d seen =
          distorted
              ? splat::distorted_position(*distorted, model_camera(cameras[v]), px.x(), px.y())
              : px;
      const Eigen::Vector3d c = cameras[v].center();
      const double dist = (hit.point - c).norm();
      const Hit h = tracer.intersect(c, (hit.point - c) / dist, true);
      if (std::abs(h.t - dist) < 1e-4 * dist + 1e-6) s.observations.emplace_back(int(v), seen);
    }
    s.valid = s.observations.size() >= 2;
  });

  splat::ColmapModel model;
  model.cameras[1] = distorted ? *distorted : model_camera(cameras.front());
  for (size_t v = 0; v < cameras.size(); ++v) {
    splat::ColmapImage im;
    im.image_id = uint32_t(v + 1);
    im.qvec = splat::quaternion_from_rotation(cameras[v].R);
    im.tvec = cameras[v].t;
    im.camera_id = 1;
    im.name = names[v];
    model.images[im.image_id] = std::move(im);
  }
  uint64_t next_id = 1;
  for (const Sample& s : samples) {
    if (!s.valid) continue;
    splat::ColmapPoint3D p;
    p.point3d_id = next_id++;
    p.xyz = s.xyz;
    for (int k = 0; k < 3; ++k)
      p.rgb[k] = uint8_t(std::lround(255 * std::clamp(s.color[k], 0.0, 1.0)));
    for (const auto& [v, px] : s.observations) {
      splat::ColmapImage& im = model.images[uint32_t(v + 1)];
      p.track.push_back({im.image_id, uint32_t(im.points2d.size())});
      im.points2d.push_back(px);
      im.point3d_ids.push_back(int64_t(p.point3d_id));
    }
    model.points3d[p.point3d_id] = std::move(p);
  }
  return model;
}

namespace {

// The camera files hold the SfM-like cameras; the points and their
// observations stay true, as a bundle adjustment leaves a small residual.
void use_posed_cameras(RenderedScene& r) {
  for (auto& [id, image] : r.sparse.images) {
    const splat::Camera& c = r.posed_cameras[id - 1];
    image.qvec = splat::quaternion_from_rotation(c.R);
    image.tvec = c.t;
  }
  splat::ColmapCamera& camera = r.sparse.cameras.begin()->second;
  camera.params[0] = r.posed_cameras.front().fx;
  camera.params[1] = r.posed_cameras.front().fy;
}

}  // namespace

RenderedScene render_scene(const SynthOptions& o, const SceneLayout& layout) {
  RenderedScene r;
  const RayTracer tracer(layout);
  r.cameras = orbit_cameras(o, layout);
  const std::string extension = o.shipping == Shipping::kOp2gs ? ".png" : ".jpg";
  for (int i = 0; i < o.views; ++i) r.names.push_back(view_name(i, extension));
  const splat::ColmapCamera lens = photo_camera(o, r.cameras.front());
  const splat::ColmapCamera* distorted = o.distortion.empty() ? nullptr : &lens;
  r.images.resize(o.views);
  r.instance_maps.resize(o.views);
  std::atomic<int> done{0};
  tbb::parallel_for(0, o.views, [&](int i) {
    render_view(tracer, r.cameras[i], o.supersample, distorted, r.images[i], r.instance_maps[i]);
    const int n = ++done;
    if (n % 10 == 0 || n == o.views) spdlog::info("rendered {}/{} views", n, o.views);
  });
  if (o.capture.photometric()) {
    const std::vector<Eigen::Vector3d> gains = view_gains(o.capture, o.views, o.seed);
    tbb::parallel_for(0, o.views, [&](int i) {
      record_photo(r.images[i], gains[i], o.capture, o.seed * 104729 + uint64_t(i));
    });
  }
  r.posed_cameras = o.capture.geometric()
                        ? sfm_like_cameras(r.cameras, o.capture, o.orbit_radius, o.seed)
                        : r.cameras;
  if (o.write_sparse || o.shipping != Shipping::kOp2gs || o.ovs_prepared) {
    r.sparse = sample_sparse_model(tracer, r.cameras, r.names, o.num_points, o.seed, distorted);
    spdlog::info("sampled {} sparse points seen from >= 2 views", r.sparse.points3d.size());
    use_posed_cameras(r);
  }
  return r;
}

namespace {

std::string stem(const std::string& name) { return fs::path(name).stem().string(); }

std::vector<uint8_t> object_mask(const splat::IdMap& m, int id) {
  std::vector<uint8_t> mask(m.ids.size());
  for (size_t i = 0; i < mask.size(); ++i) mask[i] = m.ids[i] == id;
  return mask;
}

json object_table(const SceneLayout& layout) {
  json objects = json::array();
  for (const SceneObject& o : layout.objects)
    objects.push_back({{"id", o.id},
                       {"name", o.name},
                       {"shape", shape_name(o.shape)},
                       {"opacity", o.material.opacity},
                       {"hard_case", o.hard_case}});
  return objects;
}

// LLFF poses_bounds.npy: per view a 3x5 matrix [R | t | (H, W, f)] of the
// camera-to-world pose with columns (down, right, backwards), then near, far.
void write_poses_bounds(const fs::path& file, const RenderedScene& r, const SceneLayout& layout) {
  std::vector<double> rows;
  for (const splat::Camera& c : r.posed_cameras) {
    const Eigen::Matrix3d c2w = c.R.transpose();
    Eigen::Matrix<double, 3, 5> m;
    m.col(0) = c2w.col(1);
    m.col(1) = c2w.col(0);
    m.col(2) = -c2w.col(2);
    m.col(3) = c.center();
    m.col(4) = Eigen::Vector3d(c.height, c.width, c.fx);
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 5; ++col) rows.push_back(m(row, col));
    const double far = (c.center().norm() + layout.enclosure_radius);
    rows.push_back(0.1);
    rows.push_back(far);
  }
  splat::write_npy_f64(file, rows, {r.cameras.size(), 17});
}

void write_ovs_layout(const fs::path& dir, const RenderedScene& r,
                      const std::vector<splat::IdMap>& sam2, const SceneLayout& layout,
                      int test_views, bool prepared) {
  const int n = int(r.images.size());
  const int digits = std::max(2, int(std::to_string(n - 1).size()));
  auto ovs_name = [&](int i) { return fmt::format("{:0{}d}", i, digits); };
  std::string classes;
  for (const SceneObject& o : layout.objects) classes += o.name + "\n";
  splat::write_text_atomically(dir / "segmentations" / "classes.txt", classes);
  tbb::parallel_for(0, n, [&](int i) {
    splat::write_image_rgb(dir / "images" / (ovs_name(i) + ".png"), r.images[i]);
    splat::write_id_map(dir / (prepared ? "object_mask_deva" : "sam2") / (ovs_name(i) + ".png"),
                        sam2[i], 8);
  });
  // Test views spread over the sequence; in 3DOVS they are training views too.
  for (int k = 0; k < test_views; ++k) {
    const int i = int(std::lround((k + 0.5) * n / test_views - 0.5));
    for (const SceneObject& o : layout.objects)
      splat::write_mask_png(dir / "segmentations" / ovs_name(i) / (o.name + ".png"),
                            r.images[i].width, r.images[i].height,
                            object_mask(r.instance_maps[i], o.id));
  }
  if (!prepared) {
    write_poses_bounds(dir / "poses_bounds.npy", r, layout);
    return;
  }
  splat::ColmapModel model = r.sparse;  // the true cameras, under the 3DOVS names
  for (auto& [id, image] : model.images) image.name = ovs_name(int(id) - 1) + ".png";
  splat::write_colmap_model(model, dir / "sparse" / "0", splat::ColmapFormat::kBinary);
}

// The LERF-Mask layout: op2gs's own, or Gaussian Grouping's download (DEVA
// maps in object_mask/, black on the test views; no op2gs extras).
void write_layout(const fs::path& dir, const SynthOptions& o, const SceneLayout& layout,
                  const RenderedScene& r, const std::vector<splat::IdMap>& sam2) {
  const int n = int(r.images.size());
  const bool download = o.shipping == Shipping::kLerfMaskDownload;
  tbb::parallel_for(0, n, [&](int i) {
    const bool test = i % o.test_every == 0;
    splat::write_image_rgb(dir / "images" / r.names[i], r.images[i]);
    if (!test) splat::write_image_rgb(dir / "images_train" / r.names[i], r.images[i]);
    const std::string map_name = stem(r.names[i]) + ".png";
    if (download) {
      const splat::IdMap black(sam2[i].width, sam2[i].height);
      splat::write_id_map(dir / "object_mask" / map_name, test ? black : sam2[i], 8);
      return;
    }
    splat::write_id_map(dir / "instance_gt" / map_name, r.instance_maps[i], 8);
    splat::write_id_map(dir / "sam2" / map_name, sam2[i], 8);
  });
  // test_mask/<k>/<query>.png, k = index among the test views sorted by name.
  std::set<std::string> queries;
  int k = 0;
  for (int i = 0; i < n; i += o.test_every, ++k) {
    for (const SceneObject& obj : layout.objects) {
      const auto mask = object_mask(r.instance_maps[i], obj.id);
      if (std::none_of(mask.begin(), mask.end(), [](uint8_t v) { return v; })) continue;
      splat::write_mask_png(dir / "test_mask" / std::to_string(k) / (obj.name + ".png"),
                            r.images[i].width, r.images[i].height, mask);
      queries.insert(obj.name);
    }
  }
  if (download) {
    splat::write_colmap_model(r.sparse, dir / "sparse" / "0", splat::ColmapFormat::kBinary);
    // COLMAP's leftovers that the download carries.
    splat::write_colmap_model(r.sparse, dir / "distorted" / "sparse" / "0",
                              splat::ColmapFormat::kBinary);
    for (const char* cfg : {"fusion.cfg", "patch-match.cfg"})
      splat::write_text_atomically(dir / "stereo" / cfg, "");
    return;
  }
  std::string query_list;
  for (const SceneObject& obj : layout.objects)
    if (queries.count(obj.name)) query_list += obj.name + "\n";
  splat::write_text_atomically(dir / "queries.txt", query_list);

  const json objects = object_table(layout);
  splat::write_text_atomically(dir / "objects.json", objects.dump(2) + "\n");
  json sam2_names = json::array();
  for (const SceneObject& obj : layout.objects)
    sam2_names.push_back({{"id", obj.id}, {"name", obj.name}});
  splat::write_text_atomically(dir / "sam2" / "objects.json", sam2_names.dump(2) + "\n");

  if (o.write_sparse)
    splat::write_colmap_model(r.sparse, dir / "sparse" / "0", splat::ColmapFormat::kText);

  json meta = {{"generator", "op2gs-synth"},
               {"seed", o.seed},
               {"views", o.views},
               {"width", o.width},
               {"height", o.height},
               {"supersample", o.supersample},
               {"test_every", o.test_every},
               {"fov_x_degrees", o.fov_x_degrees},
               {"orbit_radius", o.orbit_radius},
               {"orbit_height", o.orbit_height},
               {"look_at", {layout.look_at.x(), layout.look_at.y(), layout.look_at.z()}},
               {"sparse_points", r.sparse.points3d.size()},
               {"sam2",
                {{"strength", o.sam2.strength},
                 {"boundary_jitter_px", o.sam2.boundary_jitter_px},
                 {"miss_probability", o.sam2.miss_probability},
                 {"miss_radius", o.sam2.miss_radius},
                 {"leak_probability", o.sam2.leak_probability},
                 {"leak_radius", o.sam2.leak_radius},
                 {"spurious_blobs", o.sam2.spurious_blobs},
                 {"spurious_radius", o.sam2.spurious_radius},
                 {"persistence_views", o.sam2.persistence_views}}},
               {"tracks",
                {{"id_switches", o.tracks.id_switches},
                 {"switch_run_views", o.tracks.switch_run_views},
                 {"merges", o.tracks.merges},
                 {"merge_run_views", o.tracks.merge_run_views},
                 {"late_objects", o.tracks.late_objects},
                 {"late_fraction", o.tracks.late_fraction}}},
               {"capture",
                {{"exposure_stops", o.capture.exposure_stops},
                 {"white_balance", o.capture.white_balance},
                 {"drift_correlation", o.capture.drift_correlation},
                 {"noise", o.capture.noise},
                 {"jpeg_quality", o.capture.jpeg_quality},
                 {"specular", o.capture.specular},
                 {"pose_rotation_degrees", o.capture.pose_rotation_degrees},
                 {"pose_translation", o.capture.pose_translation},
                 {"focal_error", o.capture.focal_error}}}};
  splat::write_text_atomically(dir / "scene.json", meta.dump(2) + "\n");
  splat::write_text_atomically(dir / "surfaces.json", layout_to_json(layout).dump(2) + "\n");
}

// Camera to world in the OpenGL convention (x right, y up, z back), as
// transforms.json holds it.
json opengl_pose(const splat::Camera& c, const Eigen::Matrix3d& world_turn) {
  Eigen::Matrix3d r = world_turn * c.R.transpose();
  r.col(1) *= -1;
  r.col(2) *= -1;
  const Eigen::Vector3d t = world_turn * c.center();
  json m = json::array();
  for (int i = 0; i < 3; ++i) m.push_back({r(i, 0), r(i, 1), r(i, 2), t(i)});
  m.push_back({0.0, 0.0, 0.0, 1.0});
  return m;
}

// A posed capture as nerfstudio or instant-ngp writes it (generator.h).
void write_capture(const fs::path& dir, const SynthOptions& o, const SceneLayout& layout,
                   const RenderedScene& r, const std::vector<splat::IdMap>& sam2) {
  const int n = int(r.images.size());
  tbb::parallel_for(0, n, [&](int i) {
    splat::write_image_rgb(dir / "images" / r.names[i], r.images[i]);
    splat::write_id_map(dir / "sam2" / (stem(r.names[i]) + ".png"), sam2[i], 8);
  });
  json names = json::array();
  for (const SceneObject& obj : layout.objects)
    names.push_back({{"id", obj.id}, {"name", obj.name}});
  splat::write_text_atomically(dir / "sam2" / "objects.json", names.dump(2) + "\n");

  const bool ns = o.shipping == Shipping::kNerfstudio;
  // nerfstudio turns COLMAP's world (x <-> y, z flipped) and says so.
  Eigen::Matrix3d turn = Eigen::Matrix3d::Identity();
  if (ns) turn << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  const splat::Camera& c0 = r.posed_cameras.front();
  json t = {{"w", c0.width}, {"h", c0.height}, {"fl_x", c0.fx},
            {"fl_y", c0.fy}, {"cx", c0.cx},    {"cy", c0.cy}};
  if (!ns) {
    t["camera_angle_x"] = 2 * std::atan(0.5 * c0.width / c0.fx);
    t["camera_angle_y"] = 2 * std::atan(0.5 * c0.height / c0.fy);
    t["aabb_scale"] = 4;
  }
  if (!o.distortion.empty())
    for (int k = 0; k < 4; ++k) t[std::array{"k1", "k2", "p1", "p2"}[k]] = o.distortion[k];
  if (ns) {
    t["camera_model"] = o.distortion.empty() ? "PINHOLE" : "OPENCV";
    t["applied_transform"] = {{0.0, 1.0, 0.0, 0.0}, {1.0, 0.0, 0.0, 0.0}, {0.0, 0.0, -1.0, 0.0}};
    t["ply_file_path"] = "sparse_pc.ply";
  }
  json frames = json::array();
  for (int i = 0; i < n; ++i) {
    // instant-ngp's captures often name their photos without extension.
    const std::string path = "images/" + (ns ? r.names[i] : stem(r.names[i]));
    frames.push_back(
        {{"file_path", path}, {"transform_matrix", opengl_pose(r.posed_cameras[i], turn)}});
  }
  t["frames"] = frames;
  splat::write_text_atomically(dir / "transforms.json", t.dump(4) + "\n");
  if (!ns) return;
  std::string ply = fmt::format(
      "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\n"
      "property float z\nproperty uint8 red\nproperty uint8 green\nproperty uint8 blue\n"
      "end_header\n",
      r.sparse.points3d.size());
  for (const auto& [id, p] : r.sparse.points3d) {
    const Eigen::Vector3d x = turn * p.xyz;
    ply += fmt::format("{:.6f} {:.6f} {:.6f} {} {} {}\n", x.x(), x.y(), x.z(), p.rgb[0], p.rgb[1],
                       p.rgb[2]);
  }
  splat::write_text_atomically(dir / "sparse_pc.ply", ply);
}

}  // namespace

void generate_scene(const SynthOptions& o, const fs::path& out_dir, bool force) {
  o.Check();
  for (const fs::path& dir : {out_dir, o.ovs_dir})
    if (!dir.empty() && fs::exists(dir) && !force)
      throw std::runtime_error(dir.string() + ": already exists (use --force to replace it)");
  SceneLayout layout = default_layout(o.seed);
  layout.specular = o.capture.specular;
  spdlog::info("rendering {} views at {}x{} ({}x{} samples per pixel)", o.views, o.width, o.height,
               o.supersample, o.supersample);
  const RenderedScene r = render_scene(o, layout);

  std::vector<int> ids;
  for (const SceneObject& obj : layout.objects) ids.push_back(obj.id);
  std::vector<splat::IdMap> sam2 = corrupt_sequence_like_sam2(r.instance_maps, ids, o.sam2, o.seed);
  const std::vector<int> switched =
      apply_track_errors(sam2, r.instance_maps, ids, o.tracks, o.seed);
  if (!switched.empty()) spdlog::info("{} track IDs switched", switched.size());

  // Each folder is built aside and swapped in whole (--force replaces it).
  spdlog::info("writing the scene to {}", out_dir.string());
  splat::StagedFolder scene(out_dir, splat::StagedFolder::Target::kOwned);
  if (o.shipping == Shipping::kNerfstudio || o.shipping == Shipping::kInstantNgp)
    write_capture(scene.path(), o, layout, r, sam2);
  else
    write_layout(scene.path(), o, layout, r, sam2);
  scene.commit();

  if (!o.ovs_dir.empty()) {
    spdlog::info("writing the 3DOVS layout to {}", o.ovs_dir.string());
    splat::StagedFolder ovs(o.ovs_dir, splat::StagedFolder::Target::kOwned);
    write_ovs_layout(ovs.path(), r, sam2, layout, o.ovs_test_views, o.ovs_prepared);
    ovs.commit();
  }
}

}  // namespace synth
