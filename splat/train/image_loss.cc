#include "splat/train/image_loss.h"

#include <cmath>

#include "splat/image_quality.h"

namespace splat {

ImageLoss image_loss(std::span<const float> rendered, const ImageRGB& target,
                     const ImageLossOptions& options, std::vector<float>* grad) {
  const int W = target.width, H = target.height;
  const size_t n = target.data.size();
  ImageLoss loss;
  double l1 = 0;
  for (size_t i = 0; i < n; ++i) l1 += std::abs(double(rendered[i]) - target.data[i]);
  loss.l1 = l1 / n;
  if (grad) {
    grad->assign(n, 0.f);
    const float g = (1 - options.lambda_ssim) / float(n);
    for (size_t i = 0; i < n; ++i) {
      const float d = rendered[i] - target.data[i];
      (*grad)[i] = d > 0 ? g : (d < 0 ? -g : 0.f);  // torch's sign(0) = 0
    }
  }
  double ssim_sum = 0;
  for (int c = 0; c < 3; ++c) {
    const std::vector<float> x = rgb_channel(rendered, c), y = rgb_channel(target.data, c);
    std::vector<float> dx;
    if (grad) dx.assign(x.size(), 0.f);
    ssim_sum += ssim_plane(x, y, W, H, grad ? &dx : nullptr);
    if (grad) {
      // loss term lambda * (1 - mean SSIM): d/dx = -lambda / n * d(sum)/dx.
      const float scale = -options.lambda_ssim / float(n);
      for (size_t i = 0; i < dx.size(); ++i) (*grad)[3 * i + c] += scale * dx[i];
    }
  }
  loss.ssim = ssim_sum / n;
  loss.total = (1 - options.lambda_ssim) * loss.l1 + options.lambda_ssim * (1 - loss.ssim);
  return loss;
}

}  // namespace splat
