#include "synth/capture_imperfections.h"

#include <gtest/gtest.h>

#include <cmath>

namespace synth {
namespace {

TEST(CaptureImperfections, NoneByDefault) {
  const CaptureOptions o;
  EXPECT_FALSE(o.photometric());
  EXPECT_FALSE(o.geometric());
  for (const Eigen::Vector3d& g : view_gains(o, 10, 1)) EXPECT_EQ(g, Eigen::Vector3d::Ones());
}

TEST(CaptureImperfections, GainsDriftSmoothlyWithTheRequestedSpread) {
  CaptureOptions o;
  o.exposure_stops = 0.3;
  const auto gains = view_gains(o, 4000, 7);
  double sum = 0, sum2 = 0, step2 = 0;
  for (size_t i = 0; i < gains.size(); ++i) {
    const double stops = std::log2(gains[i][0]);
    EXPECT_DOUBLE_EQ(gains[i][0], gains[i][2]);  // no white balance asked for
    sum += stops, sum2 += stops * stops;
    if (i) step2 += std::pow(stops - std::log2(gains[i - 1][0]), 2);
  }
  const double n = double(gains.size());
  const double spread = std::sqrt(sum2 / n - std::pow(sum / n, 2));
  EXPECT_NEAR(spread, 0.3, 0.05);
  // Consecutive views differ by much less than the spread: a drift, not flicker.
  EXPECT_LT(std::sqrt(step2 / (n - 1)), 0.7 * spread);
}

TEST(CaptureImperfections, RecordingAppliesGainNoiseAndClipping) {
  splat::ImageRGB image(64, 64);
  for (float& v : image.data) v = 0.5f;
  CaptureOptions o;
  o.noise = 0.01;
  record_photo(image, Eigen::Vector3d(1.2, 1.0, 2.5), o, 3);
  double mean[3] = {}, var = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 3; ++c) {
        mean[c] += image.pixel(x, y)[c] / 4096.0;
        if (c == 1) var += std::pow(image.pixel(x, y)[c] - 0.5, 2) / 4096.0;
      }
  EXPECT_NEAR(mean[0], 0.6, 0.002);
  EXPECT_NEAR(mean[1], 0.5, 0.002);
  EXPECT_NEAR(mean[2], 1.0, 0.002);  // clipped
  EXPECT_NEAR(std::sqrt(var), 0.01 * std::sqrt(3.0), 0.002);
}

TEST(CaptureImperfections, JpegKeepsThePictureClose) {
  splat::ImageRGB image(64, 48);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 3; ++c)
        image.pixel(x, y)[c] = 0.5f + 0.4f * std::sin(0.2f * x + c) * std::cos(0.15f * y);
  const splat::ImageRGB before = image;
  CaptureOptions o;
  o.jpeg_quality = 90;
  record_photo(image, Eigen::Vector3d::Ones(), o, 1);
  double err = 0;
  for (size_t i = 0; i < image.data.size(); ++i) err += std::abs(image.data[i] - before.data[i]);
  err /= double(image.data.size());
  EXPECT_GT(err, 0.0);
  EXPECT_LT(err, 0.01);  // under 3 / 255 on a smooth picture
}

TEST(CaptureImperfections, CameraFilesErrIndependentlyOfThePhotos) {
  std::vector<splat::Camera> truth;
  for (int i = 0; i < 200; ++i) {
    const double a = 0.1 * i;
    truth.push_back(splat::Camera::look_at({3 * std::cos(a), 1, 3 * std::sin(a)}, {0, 0, 0},
                                           {0, 1, 0}, 640, 480, 600, 600));
  }
  CaptureOptions o;
  o.pose_rotation_degrees = 0.2;
  o.pose_translation = 0.01;
  o.focal_error = 0.01;
  const auto posed = sfm_like_cameras(truth, o, 3.0, 5);
  double angle2 = 0, shift2 = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    const Eigen::Matrix3d d = posed[i].R * truth[i].R.transpose();
    angle2 += std::pow(std::acos(std::clamp((d.trace() - 1) / 2, -1.0, 1.0)), 2);
    shift2 += (posed[i].center() - truth[i].center()).squaredNorm();
    EXPECT_EQ(posed[i].fx / truth[i].fx, posed[0].fx / truth[0].fx);  // one shared error
  }
  // Rotation angle of three axes of standard deviation s: RMS s * sqrt(3).
  EXPECT_NEAR(std::sqrt(angle2 / 200) * 180 / M_PI, 0.2 * std::sqrt(3.0), 0.06);
  EXPECT_NEAR(std::sqrt(shift2 / 200), 0.03 * std::sqrt(3.0), 0.01);
  EXPECT_NE(posed[0].fx, truth[0].fx);
}

TEST(CaptureImperfections, TypicalIsValidAndBadValuesAreRefused) {
  EXPECT_NO_THROW(CaptureOptions::typical().Check());
  CaptureOptions o;
  o.jpeg_quality = 101;
  EXPECT_THROW(o.Check(), std::invalid_argument);
  o = {};
  o.noise = -1;
  EXPECT_THROW(o.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace synth
