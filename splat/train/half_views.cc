#include "splat/train/half_views.h"

#include <stdexcept>

namespace splat {

void HalfViewOptions::Check() const {
  if (from_iteration < 0)
    throw std::invalid_argument("the half views' first iteration must be >= 0 (0: off)");
}

PixelRect training_half(int width, int height, size_t view, int iteration, size_t training_views) {
  if (width < 2 || height < 2 || training_views == 0)
    throw std::invalid_argument("training_half: a view of at least 2x2 pixels expected");
  const size_t epoch = size_t(iteration > 0 ? iteration - 1 : 0) / training_views;
  const bool second = (epoch + view) % 2 == 1;
  if (width >= height) {
    const int left = width / 2;
    return second ? PixelRect{left, 0, width - left, height} : PixelRect{0, 0, left, height};
  }
  const int top = height / 2;
  return second ? PixelRect{0, top, width, height - top} : PixelRect{0, 0, width, top};
}

double half_share(const PixelRect& half, int width, int height) {
  return double(half.width) * half.height / (double(width) * height);
}

}  // namespace splat
