#include "splat/spz.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "splat/error.h"
#include "tests/test_util.h"

namespace splat {
namespace {

using testing_util::read_file;
using testing_util::TempDir;
using testing_util::write_file;

// A model with the value ranges of trained ones.
GaussianModel trained_like_model(size_t n) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  GaussianModel m;
  m.resize(n);
  for (float& x : m.means) x = 20.f * u(rng);
  for (float& x : m.sh_dc) x = 1.5f * u(rng);
  for (float& x : m.sh_rest) x = 0.3f * u(rng);
  for (float& x : m.opacity_logits) x = 4.f * u(rng);
  for (float& x : m.log_scales) x = -4.f + 3.f * u(rng);
  for (float& x : m.rotations) x = u(rng);
  return m;
}

float max_difference(const std::vector<float>& a, const std::vector<float>& b) {
  float d = 0;
  for (size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

TEST(Spz, ReadBackWithinEachEncodingsStep) {
  TempDir dir;
  const GaussianModel m = trained_like_model(2000);
  write_spz(dir / "m.spz", m);
  const GaussianModel back = read_spz(dir / "m.spz");
  ASSERT_EQ(back.size(), m.size());
  EXPECT_LE(max_difference(back.means, m.means), 0.5f / 4096 * 2);  // 11 fractional bits at 20
  EXPECT_LE(max_difference(back.sh_dc, m.sh_dc), 0.5f / (0.15f * 255) + 1e-5f);
  EXPECT_LE(max_difference(back.log_scales, m.log_scales), 0.5f / 16 + 1e-5f);
  EXPECT_LE(max_difference(back.sh_rest, m.sh_rest), 8.5f / 128 + 1e-5f);  // 4-bit buckets
  for (size_t i = 0; i < m.size(); ++i) {
    EXPECT_NEAR(sigmoid(back.opacity_logits[i]), sigmoid(m.opacity_logits[i]), 0.5f / 255 + 1e-4f);
    // The same rotation: unit quaternions equal up to sign.
    const float* a = &m.rotations[4 * i];
    const float* b = &back.rotations[4 * i];
    const float na = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2] + a[3] * a[3]);
    const float dot = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]) / na;
    EXPECT_GT(std::abs(dot), 0.99f) << i;
  }
}

TEST(Spz, FarCoordinatesKeepTheirPlace) {
  TempDir dir;
  GaussianModel m = trained_like_model(10);
  m.means[0] = 30000.f;  // beyond 12 fractional bits' 2048
  m.means[1] = -5000.f;
  write_spz(dir / "m.spz", m);
  const GaussianModel back = read_spz(dir / "m.spz");
  EXPECT_NEAR(back.means[0], 30000.f, 0.1f);
  EXPECT_NEAR(back.means[1], -5000.f, 0.1f);
}

TEST(Spz, IsMuchSmallerThanThePly) {
  TempDir dir;
  write_spz(dir / "m.spz", trained_like_model(10000));
  // 248 bytes per Gaussian in a PLY; 64 before compression here.
  EXPECT_LT(std::filesystem::file_size(dir / "m.spz"), 10000u * 64);
}

TEST(Spz, MalformedFilesAreRefusedNamingTheFile) {
  TempDir dir;
  write_spz(dir / "m.spz", trained_like_model(100));
  const std::string bytes = read_file(dir / "m.spz");
  write_file(dir / "truncated.spz", bytes.substr(0, bytes.size() / 2));
  write_file(dir / "text.spz", "not gzip at all");
  for (const char* name : {"truncated.spz", "text.spz"}) {
    try {
      read_spz(dir / name);
      FAIL() << name;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace splat
