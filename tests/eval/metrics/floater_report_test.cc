// floaters.json: what op2gs-floaters writes, op2gs-report reads back whole.

#include "eval/metrics/floater_report.h"

#include <gtest/gtest.h>

#include "splat/error.h"
#include "tests/test_util.h"

namespace eval {
namespace {

FloaterReport a_report() {
  FloaterReport r;
  r.distance = 0.05;
  r.gaussians = 1000;
  r.floaters = 120;
  r.floaters_labelled = 7;
  r.region_gaussians = 400;
  r.region_floaters = 30;
  r.floater_opacity_share = 0.125;
  r.region_floater_opacity_share = 0.0625;
  r.mask_floater_share_sigma = 0.03;
  r.mask_floater_share_sigma_star = 0.01;
  r.mask_wrong_share_sigma = 0.061;
  r.mask_wrong_share_sigma_star = 0.017;
  r.view_names = {"frame_00000.png", "frame_00008.png"};
  r.view_floater_opacity_share = {0.1, 0.15};
  r.view_region_floater_opacity_share = {0.05, 0.075};
  ObjectContamination named{1, "red ball", 300, 4, 310, 14, 3, 9, 0.6, 0.1, 0.8, 0.85};
  ObjectContamination unnamed{7, "", 0, 0, 2, 2, 2, 0, 0.3, 0.2, 0, 0};
  r.objects = {named, unnamed};
  return r;
}

void expect_same(const FloaterReport& a, const FloaterReport& b) {
  EXPECT_EQ(a.distance, b.distance);
  EXPECT_EQ(a.gaussians, b.gaussians);
  EXPECT_EQ(a.floaters, b.floaters);
  EXPECT_EQ(a.floaters_labelled, b.floaters_labelled);
  EXPECT_EQ(a.region_gaussians, b.region_gaussians);
  EXPECT_EQ(a.region_floaters, b.region_floaters);
  EXPECT_EQ(a.floater_opacity_share, b.floater_opacity_share);
  EXPECT_EQ(a.region_floater_opacity_share, b.region_floater_opacity_share);
  EXPECT_EQ(a.mask_floater_share_sigma, b.mask_floater_share_sigma);
  EXPECT_EQ(a.mask_floater_share_sigma_star, b.mask_floater_share_sigma_star);
  EXPECT_EQ(a.mask_wrong_share_sigma, b.mask_wrong_share_sigma);
  EXPECT_EQ(a.mask_wrong_share_sigma_star, b.mask_wrong_share_sigma_star);
  EXPECT_EQ(a.view_names, b.view_names);
  EXPECT_EQ(a.view_floater_opacity_share, b.view_floater_opacity_share);
  EXPECT_EQ(a.view_region_floater_opacity_share, b.view_region_floater_opacity_share);
  ASSERT_EQ(a.objects.size(), b.objects.size());
  for (size_t i = 0; i < a.objects.size(); ++i) {
    const ObjectContamination &x = a.objects[i], &y = b.objects[i];
    EXPECT_EQ(x.id, y.id);
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.gaussians, y.gaussians);
    EXPECT_EQ(x.wrong, y.wrong);
    EXPECT_EQ(x.labelled, y.labelled);
    EXPECT_EQ(x.labelled_wrongly, y.labelled_wrongly);
    EXPECT_EQ(x.labelled_floaters, y.labelled_floaters);
    EXPECT_EQ(x.labelled_border, y.labelled_border);
    EXPECT_EQ(x.mean_sigma_wrong, y.mean_sigma_wrong);
    EXPECT_EQ(x.mean_sigma_star_wrong, y.mean_sigma_star_wrong);
    EXPECT_EQ(x.mean_sigma_right, y.mean_sigma_right);
    EXPECT_EQ(x.mean_sigma_star_right, y.mean_sigma_star_right);
  }
}

TEST(FloaterReport, ReadsBackWhatItWrote) {
  testing_util::TempDir dir;
  const FloaterReport r = a_report();
  write_floater_report(dir / "floaters.json", r);
  expect_same(read_floater_report(dir / "floaters.json"), r);
  // Without rendered views there is no per-view part.
  FloaterReport unrendered = r;
  unrendered.view_names.clear();
  unrendered.view_floater_opacity_share.clear();
  unrendered.view_region_floater_opacity_share.clear();
  write_floater_report(dir / "unrendered.json", unrendered);
  expect_same(read_floater_report(dir / "unrendered.json"), unrendered);
}

TEST(FloaterReport, AnotherFileIsAnInputErrorNamingIt) {
  testing_util::TempDir dir;
  testing_util::write_file(dir / "floaters.json", R"({"distance": 0.05, "gaussians": 3})");
  try {
    read_floater_report(dir / "floaters.json");
    FAIL() << "expected an error";
  } catch (const splat::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("floaters.json"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace eval
