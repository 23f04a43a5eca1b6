#pragma once
// The generator's last step: one writer per output format of a rendered
// scene with its segmenter-like ID maps (`sam2`, one per view) (generator.h
// lists the files of each).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "splat/id_maps.h"
#include "synth/generator.h"
#include "synth/render_scene.h"
#include "synth/world.h"

namespace synth {

// op2gs's LERF-Mask layout, or Gaussian Grouping's LERF-Mask download
// (o.format).
void write_lerf_mask_layout(const std::filesystem::path& dir, const SynthOptions& o,
                            const World& world, const RenderedScene& r,
                            const std::vector<splat::IdMap>& sam2);

// The 3DOVS layout as released (poses_bounds.npy, segmentations/) or as the
// 3DGS papers prepare it (sparse/0/, object_mask_deva/).
void write_ovs_layout(const std::filesystem::path& dir, const RenderedScene& r,
                      const std::vector<splat::IdMap>& sam2, const World& world, int test_views,
                      bool prepared);

// A posed capture as nerfstudio or instant-ngp writes it (transforms.json).
void write_capture(const std::filesystem::path& dir, const SynthOptions& o, const World& world,
                   const RenderedScene& r, const std::vector<splat::IdMap>& sam2);

// Helpers the writers share: a file name without its extension, and one
// object's binary mask (1 inside) of an ID map.
std::string file_stem(const std::string& name);
std::vector<uint8_t> object_mask(const splat::IdMap& m, int id);

}  // namespace synth
