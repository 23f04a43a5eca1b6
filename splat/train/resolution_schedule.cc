#include "splat/train/resolution_schedule.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace splat {

void ResolutionScheduleOptions::Check() const {
  if (!(start_downscale >= 1))
    throw std::invalid_argument("the resolution schedule's start downscale must be >= 1");
  if (full_from < 0)
    throw std::invalid_argument("the resolution schedule's full-resolution iteration must be >= 0");
}

double training_downscale(const ResolutionScheduleOptions& options, int iteration) {
  if (!options.enabled() || iteration >= options.full_from) return 1;
  const double t = std::clamp(double(iteration) / options.full_from, 0.0, 1.0);
  return std::exp((1 - t) * std::log(options.start_downscale));
}

}  // namespace splat
