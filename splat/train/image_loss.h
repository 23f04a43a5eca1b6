#pragma once
// The reference 3DGS photometric loss and its exact gradient:
//   loss = (1 - 0.2) * L1 + 0.2 * (1 - SSIM),
// SSIM with an 11x11 Gaussian window (sigma 1.5), C1 = 0.01^2, C2 = 0.03^2,
// zero padding at the borders (PyTorch's conv2d with padding 5, as the
// reference computes it), averaged over pixels and channels.

#include <array>
#include <span>
#include <vector>

#include "splat/huge_page_allocator.h"
#include "splat/image.h"

namespace splat {

struct ImageLossOptions {
  float lambda_ssim = 0.2f;
};

struct ImageLoss {
  double l1 = 0;     // mean absolute error
  double mse = 0;    // mean squared error (the training view's PSNR, free with the L1 pass)
  double ssim = 0;   // mean SSIM
  double total = 0;  // (1 - lambda) * l1 + lambda * (1 - ssim)
};

// The planes image_loss works in, kept from call to call: at 1K resolution
// they are tens of MB, and allocating them for every iteration cost as much
// as the arithmetic (page faults, clearing).
struct ImageLossBuffers {
  // Planes of rows padded to a cache line (image_loss.cc's row_stride); x,
  // y and d_stats, which the horizontal blur reads, with zeros around each
  // row (its margin planes).
  ImageBuffer<float> x[3], y[3];  // the render and the photo, channel by channel
  ImageBuffer<float> blurred[5];  // x, y, x^2, y^2, xy of one channel after the horizontal pass
  ImageBuffer<float> d_stats[3];  // dS/d(mu_x), dS/d(E[x^2]), dS/d(E[xy]) per pixel
  ImageBuffer<float> d_ssim[3];  // d(SSIM map sum)/dx per channel, added to the gradient at the end
  std::vector<double> band_sums;       // per band of rows, summed in order
  std::array<int, 3> margin_layout{};  // width, height, gradient: the margins written for
};

// Loss of rendered (interleaved RGB, W x H) against target; when grad is not
// null it receives dLoss/d(rendered), same layout. The result does not depend
// on the number of threads. splat/image_quality.h's ssim_plane is the slow
// reference this is tested against.
ImageLoss image_loss(std::span<const float> rendered, const ImageRGB& target,
                     const ImageLossOptions& options, std::vector<float>* grad,
                     ImageLossBuffers* buffers = nullptr);

}  // namespace splat
