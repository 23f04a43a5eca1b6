#include "synth/render_scene.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <random>
#include <set>

#include "splat/camera_distortion.h"
#include "synth/raytracer.h"

namespace synth {
namespace fs = std::filesystem;

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

std::vector<splat::Camera> orbit_cameras(const SynthOptions& o, const World& world) {
  std::mt19937_64 rng(o.seed * 7919 + 1);
  std::uniform_real_distribution<double> u(-1, 1);
  const double fx = 0.5 * o.width / std::tan(0.5 * o.fov_x_degrees * M_PI / 180.0);
  std::vector<splat::Camera> cams;
  for (int i = 0; i < o.views; ++i) {
    const double angle = 2 * M_PI * (i + 0.3 * u(rng)) / o.views;
    const double r = o.orbit_radius * (1 + o.radius_jitter * u(rng));
    const double h = o.orbit_height + o.height_jitter * u(rng);
    const Eigen::Vector3d eye =
        world.look_at + Eigen::Vector3d(r * std::cos(angle), 0, r * std::sin(angle));
    const Eigen::Vector3d target =
        world.look_at + 0.1 * Eigen::Vector3d(u(rng), 0.5 * u(rng), u(rng));
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

RenderedScene render_scene(const SynthOptions& o, const World& world) {
  RenderedScene r;
  const RayTracer tracer(world);
  r.cameras = orbit_cameras(o, world);
  const std::string extension = o.format == OutputFormat::kOp2gs ? ".png" : ".jpg";
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
  if (o.write_sparse || o.format != OutputFormat::kOp2gs || o.ovs_prepared) {
    r.sparse = sample_sparse_model(tracer, r.cameras, r.names, o.num_points, o.seed, distorted);
    spdlog::info("sampled {} sparse points seen from >= 2 views", r.sparse.points3d.size());
    use_posed_cameras(r);
  }
  return r;
}

}  // namespace synth
