#pragma once
// The reference 3DGS photometric loss and its exact gradient:
//   loss = (1 - 0.2) * L1 + 0.2 * (1 - SSIM),
// SSIM with an 11x11 Gaussian window (sigma 1.5), C1 = 0.01^2, C2 = 0.03^2,
// zero padding at the borders (PyTorch's conv2d with padding 5, as the
// reference computes it), averaged over pixels and channels.

#include <span>
#include <vector>

#include "splat/image.h"

namespace splat {

struct ImageLossOptions {
  float lambda_ssim = 0.2f;
};

struct ImageLoss {
  double l1 = 0;     // mean absolute error
  double ssim = 0;   // mean SSIM
  double total = 0;  // (1 - lambda) * l1 + lambda * (1 - ssim)
};

// Loss of rendered (interleaved RGB, W x H) against target; when grad is not
// null it receives dLoss/d(rendered), same layout.
ImageLoss image_loss(std::span<const float> rendered, const ImageRGB& target,
                     const ImageLossOptions& options, std::vector<float>* grad);

}  // namespace splat
