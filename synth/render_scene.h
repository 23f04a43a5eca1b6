#pragma once
// Rendering the synthetic world: the orbit of cameras, the ray-traced photos
// and exact ID maps, and the sparse model, in memory (the first of the
// generator's three steps, generator.h).

#include <filesystem>
#include <string>
#include <vector>

#include "splat/camera.h"
#include "splat/colmap_model.h"
#include "splat/id_maps.h"
#include "splat/image.h"
#include "synth/generator.h"
#include "synth/world.h"

namespace synth {

// The orbit of cameras, one per view, in view order.
std::vector<splat::Camera> orbit_cameras(const SynthOptions& options, const World& world);

// Image file name of view i ("frame_00007.png", or .jpg).
std::string view_name(int i, const std::string& extension = ".png");

// Ray-traced images, exact ID maps and the sparse model of a scene, in memory.
struct RenderedScene {
  std::vector<splat::Camera> cameras;        // the true cameras, which rendered the photos
  std::vector<splat::Camera> posed_cameras;  // as the camera files hold them (SfM-like error)
  std::vector<std::string> names;
  std::vector<splat::ImageRGB> images;
  std::vector<splat::IdMap> instance_maps;
  splat::ColmapModel sparse;
};

class RayTracer;
RenderedScene render_scene(const SynthOptions& options, const World& world);

// The COLMAP camera of the photos: PINHOLE, or OPENCV with the distortion.
splat::ColmapCamera photo_camera(const SynthOptions& options, const splat::Camera& pinhole);

// Surface points seen from at least two views, with COLMAP tracks.
splat::ColmapModel sample_sparse_model(const RayTracer& tracer,
                                       const std::vector<splat::Camera>& cameras,
                                       const std::vector<std::string>& names, int num_points,
                                       uint64_t seed,
                                       const splat::ColmapCamera* distorted = nullptr);

}  // namespace synth
