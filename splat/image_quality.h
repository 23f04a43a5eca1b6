#pragma once
// Image quality of a render against its photo: PSNR, and SSIM as the
// reference 3DGS computes it (11x11 Gaussian window, sigma 1.5,
// C1 = 0.01^2, C2 = 0.03^2, zero padding at the borders, as PyTorch's
// conv2d with padding 5), averaged over pixels and channels. The training
// loss (splat/train/image_loss.h) uses the same SSIM with its gradient.

#include <span>
#include <vector>

namespace splat {

// Mean SSIM of two interleaved RGB images of width x height, and PSNR in dB
// of images in [0, 1].
double ssim(std::span<const float> a, std::span<const float> b, int width, int height);
double psnr(std::span<const float> a, std::span<const float> b);

// SSIM of one channel plane (W x H): the sum of the SSIM map and, when dx is
// not null, d(sum of the SSIM map)/dx added to dx.
double ssim_plane(const std::vector<float>& x, const std::vector<float>& y, int W, int H,
                  std::vector<float>* dx);

// Channel c of an interleaved RGB image, as a plane.
std::vector<float> rgb_channel(std::span<const float> rgb, int c);

}  // namespace splat
