#include "splat/train/resolution_schedule.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "splat/train/recipe.h"

namespace splat {
namespace {

TEST(ResolutionSchedule, OffRendersEveryIterationAtFullResolution) {
  const ResolutionScheduleOptions off;
  EXPECT_FALSE(off.enabled());
  for (int it : {0, 1, 500, 30000}) EXPECT_EQ(training_downscale(off, it), 1.0);
  // A start of 1 is off too, whatever the end.
  EXPECT_EQ(training_downscale({1.0, 1000}, 10), 1.0);
}

TEST(ResolutionSchedule, FallsLogLinearlyToFullResolution) {
  const ResolutionScheduleOptions o{4.0, 1000};
  EXPECT_DOUBLE_EQ(training_downscale(o, 0), 4.0);
  EXPECT_NEAR(training_downscale(o, 500), 2.0, 1e-12);  // halfway in log: sqrt(4)
  EXPECT_NEAR(training_downscale(o, 250), std::pow(4.0, 0.75), 1e-12);
  EXPECT_EQ(training_downscale(o, 1000), 1.0);
  EXPECT_EQ(training_downscale(o, 5000), 1.0);
  double last = 4.0;
  for (int it = 1; it < 1000; ++it) {
    const double d = training_downscale(o, it);
    EXPECT_LE(d, last) << "iteration " << it;
    EXPECT_GT(d, 1.0) << "iteration " << it;
    last = d;
  }
}

TEST(ResolutionSchedule, RejectsAStartBelowOne) {
  EXPECT_THROW((ResolutionScheduleOptions{0.5, 100}.Check()), std::invalid_argument);
  EXPECT_THROW((ResolutionScheduleOptions{2.0, -1}.Check()), std::invalid_argument);
  EXPECT_NO_THROW((ResolutionScheduleOptions{2.0, 100}.Check()));
}

TEST(Recipe, PaperChangesNothingAndFastFollowsTheSchedule) {
  TrainOptions paper;
  apply_recipe(TrainRecipe::kPaper, paper);
  EXPECT_FALSE(paper.sparse_adam);
  EXPECT_FALSE(paper.resolution_schedule.enabled());
  EXPECT_FALSE(paper.half_views.applies(30000));

  TrainOptions fast;  // the paper's 30,000 iterations, densification until 15,000
  apply_recipe(TrainRecipe::kFast, fast);
  EXPECT_TRUE(fast.sparse_adam);
  EXPECT_EQ(fast.resolution_schedule.start_downscale, 4.0);
  EXPECT_EQ(fast.resolution_schedule.full_from, 7500);
  EXPECT_EQ(fast.half_views.from_iteration, 7500);  // half views from full resolution on

  TrainOptions short_run;  // a schedule shorter than the densification window
  short_run.total_iterations = 7000;
  apply_recipe(TrainRecipe::kFast, short_run);
  EXPECT_EQ(short_run.resolution_schedule.full_from, 3500);
  EXPECT_EQ(paper.lr_position_hold_until, 0);
  EXPECT_EQ(fast.lr_position_hold_until, 0);
}

// The dash recipe: full resolution and half views where densification ends,
// the position learning rate held until the views are half size.
TEST(Recipe, DashRisesOverTheWholeWindowAndHoldsThePositionRate) {
  TrainOptions dash;
  apply_recipe(TrainRecipe::kDash, dash);
  EXPECT_TRUE(dash.sparse_adam);
  EXPECT_EQ(dash.resolution_schedule.start_downscale, 4.0);
  EXPECT_EQ(dash.resolution_schedule.full_from, 15000);
  EXPECT_EQ(dash.half_views.from_iteration, 15000);
  EXPECT_EQ(dash.lr_position_hold_until, 7500);
  EXPECT_NEAR(training_downscale(dash.resolution_schedule, 7500), 2.0, 1e-9);

  TrainOptions short_run;
  short_run.total_iterations = 7000;
  apply_recipe(TrainRecipe::kDash, short_run);
  EXPECT_EQ(short_run.resolution_schedule.full_from, 7000);
  EXPECT_EQ(short_run.lr_position_hold_until, 3500);
  EXPECT_NO_THROW(short_run.Check());
}

// What a user gives beside a recipe keeps its value, 0 (off) included; the
// recipe sets the rest.
TEST(Recipe, KeepsTheOptionsAUserGave) {
  GivenTrainOptions given;
  given.half_views_from = 0;
  given.lr_position_hold_until = 3750;
  TrainOptions fast;
  apply_recipe(TrainRecipe::kFast, fast, given);
  EXPECT_FALSE(fast.half_views.applies(30000));
  EXPECT_EQ(fast.lr_position_hold_until, 3750);
  EXPECT_TRUE(fast.sparse_adam);
  EXPECT_EQ(fast.resolution_schedule.full_from, 7500);

  given = {};
  given.sparse_adam = false;
  given.lr_position_hold_until = 0;
  TrainOptions dash;
  apply_recipe(TrainRecipe::kDash, dash, given);
  EXPECT_FALSE(dash.sparse_adam);
  EXPECT_EQ(dash.lr_position_hold_until, 0);
  EXPECT_EQ(dash.half_views.from_iteration, 15000);

  given = {};
  given.half_views_from = 1000;
  TrainOptions paper;
  apply_recipe(TrainRecipe::kPaper, paper, given);
  EXPECT_EQ(paper.half_views.from_iteration, 1000);
  EXPECT_FALSE(paper.sparse_adam);
}

TEST(TrainOptions, RejectsAPositionRateHoldOutsideTheSchedule) {
  TrainOptions o;
  o.lr_position_hold_until = -1;
  EXPECT_THROW(o.Check(), std::invalid_argument);
  o.lr_position_hold_until = o.total_iterations;
  EXPECT_THROW(o.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace splat
