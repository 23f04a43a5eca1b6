#pragma once
// A resolution schedule for stage one (the fast recipe; after DashGaussian,
// CVPR 2025): while the model is coarse, each training view is rendered and
// compared with fewer pixels, and the render's cost falls with them. The
// downscale factor falls log-linearly, as the learning rates do, from
// `start_downscale` at iteration 0 to 1 at `full_from`, and stays 1 after.
// Test views are always rendered at full resolution.

namespace splat {

struct ResolutionScheduleOptions {
  double start_downscale = 1;  // 1: every iteration at full resolution (the paper)
  int full_from = 0;           // the first iteration at full resolution

  bool enabled() const { return start_downscale > 1 && full_from > 0; }
  void Check() const;  // throws std::invalid_argument with a one-line message
};

// The factor by which the training render of `iteration` is smaller than the
// view in each dimension (>= 1; not an integer in general).
double training_downscale(const ResolutionScheduleOptions& options, int iteration);

}  // namespace splat
