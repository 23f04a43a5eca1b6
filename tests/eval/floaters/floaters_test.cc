// Floaters and contamination against the true surfaces, on Gaussians placed
// by hand in the default synthetic world.

#include "eval/floaters/floaters.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

namespace study {
namespace {

// Small isotropic Gaussians at the given centres, labelled.
splat::GaussianModel gaussians(const std::vector<Eigen::Vector3f>& centres,
                               const std::vector<int32_t>& labels, float scale = 0.01f) {
  splat::GaussianModel m;
  m.resize(centres.size());
  for (size_t j = 0; j < centres.size(); ++j) {
    for (int k = 0; k < 3; ++k) {
      m.means[3 * j + k] = centres[j][k];
      m.log_scales[3 * j + k] = std::log(scale);
      m.sh_dc[3 * j + k] = 0.5f;
    }
    m.opacity_logits[j] = splat::logit(0.9f);
  }
  m.labels = labels;
  m.has_labels = true;
  return m;
}

const synth::World& world() {
  static const synth::World l = synth::default_world(1);
  return l;
}

// Red ball (ID 1): centre (-0.9, 0.32, 0.4), radius 0.32. Blue crate (ID 2):
// centre (0.55, 0.30, -0.50), half size 0.3.
const std::vector<Eigen::Vector3f> kCentres = {
    {-0.9f + 0.32f, 0.32f, 0.4f},         // on the red ball
    {0.0f, 1.6f, 0.0f},                   // in the air above everything
    {0.55f, 0.30f, -0.50f},               // inside the blue crate, far from its faces
    {2.0f, 0.005f, 2.0f},                 // on the ground
    {-0.9f, 0.32f + 0.32f + 0.2f, 0.4f},  // 0.2 above the red ball
};

TEST(Floaters, GaussiansAreMatchedToTheirSurfaces) {
  const SurfaceMatch m = match_surfaces(gaussians(kCentres, {1, 0, 2, 0, 0}), world(), {});
  EXPECT_EQ(m.floater, (std::vector<uint8_t>{0, 1, 0, 0, 1}));
  EXPECT_EQ(m.true_object, (std::vector<int32_t>{1, 0, 2, 0, 0}));
  EXPECT_EQ(m.in_region[0], 1);
  EXPECT_EQ(m.in_region[1], 1);
  EXPECT_EQ(m.in_region[3], 0);  // 2.8 from the look-at point: beyond the objects
}

TEST(Floaters, TheDistanceDecidesWhatFloats) {
  FloaterOptions far;
  far.distance = 0.3;  // the Gaussian 0.2 above the ball is near enough now
  const SurfaceMatch m = match_surfaces(gaussians(kCentres, {1, 0, 2, 0, 0}), world(), far);
  EXPECT_EQ(m.floater[4], 0);
  EXPECT_EQ(m.true_object[4], 1);
}

TEST(Floaters, WrongLabelsAreCountedPerObject) {
  // The floater above the ball carries the ball's label; the ground Gaussian
  // the crate's.
  const FloaterReport r =
      measure_floaters(gaussians(kCentres, {1, 0, 2, 2, 1}), world(), {}, FloaterOptions{});
  EXPECT_EQ(r.gaussians, 5u);
  EXPECT_EQ(r.floaters, 2u);
  EXPECT_EQ(r.floaters_labelled, 1u);
  for (const ObjectContamination& c : r.objects) {
    if (c.id == 1) {
      EXPECT_EQ(c.gaussians, 1u);
      EXPECT_EQ(c.labelled, 2u);
      EXPECT_EQ(c.labelled_wrongly, 1u);
      EXPECT_EQ(c.labelled_floaters, 1u);
    }
    if (c.id == 2) {
      EXPECT_EQ(c.labelled, 2u);
      EXPECT_EQ(c.labelled_wrongly, 1u);  // the ground Gaussian
      EXPECT_EQ(c.labelled_floaters, 0u);
    }
  }
}

TEST(Floaters, SharesOfThePictureAndOfTheMasks) {
  // A big floater in front of the ball, labelled as the ball, and the ball's
  // own Gaussian behind it; sigma* of the floater is low (stage two).
  const Eigen::Vector3f ball(-0.9f, 0.32f, 0.4f);
  splat::GaussianModel m = gaussians(
      {ball + Eigen::Vector3f(0, 0, 0.32f), ball + Eigen::Vector3f(0, 0, 1.0f)}, {1, 1}, 0.1f);
  m.instance_opacity_logits = {splat::logit(0.9f), splat::logit(0.05f)};
  m.has_instance_opacity = true;
  const splat::Camera camera =
      splat::Camera::look_at((ball + Eigen::Vector3f(0, 0, 3)).cast<double>(), ball.cast<double>(),
                             {0, 1, 0}, 64, 64, 64, 64);
  const FloaterReport r = measure_floaters(m, world(), {camera}, FloaterOptions{});
  EXPECT_EQ(r.floaters, 1u);
  EXPECT_GT(r.floater_opacity_share, 0.5);  // in front: it takes most of the light
  // One view: its own share is the pooled one.
  ASSERT_EQ(r.view_floater_opacity_share.size(), 1u);
  EXPECT_DOUBLE_EQ(r.view_floater_opacity_share[0], r.floater_opacity_share);
  ASSERT_EQ(r.view_region_floater_opacity_share.size(), 1u);
  EXPECT_DOUBLE_EQ(r.view_region_floater_opacity_share[0], r.region_floater_opacity_share);
  EXPECT_GT(r.mask_floater_share_sigma, 0.5);
  EXPECT_LT(r.mask_floater_share_sigma_star, 0.3);  // sigma* hides it from the mask
  EXPECT_DOUBLE_EQ(r.mask_wrong_share_sigma, r.mask_floater_share_sigma);
}

TEST(Floaters, SurfacesRoundTripThroughJson) {
  const synth::World back = synth::world_from_json(synth::world_to_json(world()));
  ASSERT_EQ(back.objects.size(), world().objects.size());
  EXPECT_EQ(back.objects[3].shape, world().objects[3].shape);
  EXPECT_EQ(back.objects[3].position, world().objects[3].position);
  EXPECT_EQ(back.objects[3].half_size, world().objects[3].half_size);
  EXPECT_EQ(back.objects[8].material.opacity, world().objects[8].material.opacity);
  nlohmann::json bad = synth::world_to_json(world());
  bad["objects"][0]["shape"] = "torus";
  EXPECT_THROW(synth::world_from_json(bad), std::invalid_argument);
}

}  // namespace
}  // namespace study
