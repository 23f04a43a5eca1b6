#include "eval/metrics/mask_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "splat/id_maps.h"
#include "splat/image_codec.h"

namespace eval {
namespace fs = std::filesystem;

size_t Mask::count() const {
  size_t n = 0;
  for (uint8_t v : on) n += v;
  return n;
}

splat::IdMap read_grey_like_pillow(const fs::path& file) {
  splat::ImageFileReader in(file);
  const splat::ImageFileSpec& spec = in.spec();
  const int channels = spec.channels;
  const bool sixteen = spec.type == splat::SampleType::uint16;
  // Read in the file's own scale (8 or 16 bit, no conversion) so that the
  // luma and clipping below match Pillow's integer arithmetic.
  std::vector<uint8_t> px8;
  std::vector<uint16_t> px16;
  if (sixteen)
    px16 = in.read_all<uint16_t>(splat::SampleType::uint16);
  else
    px8 = in.read_all<uint8_t>(splat::SampleType::uint8);
  splat::IdMap grey(spec.width, spec.height);
  const auto v8 = [&](size_t i) { return sixteen ? std::min<int>(px16[i], 255) : px8[i]; };
  for (size_t p = 0; p < grey.ids.size(); ++p) {
    const size_t c = p * channels;
    grey.ids[p] = uint16_t(
        channels >= 3 ? (19595 * v8(c) + 38470 * v8(c + 1) + 7471 * v8(c + 2) + 0x8000) >> 16
                      : v8(c));
  }
  return grey;
}

Mask read_mask(const fs::path& file) {
  const splat::IdMap grey = read_grey_like_pillow(file);
  Mask m(grey.width, grey.height);
  for (size_t p = 0; p < m.on.size(); ++p) m.on[p] = grey.ids[p] > 128;
  return m;
}

Mask resize_mask_nearest(const Mask& mask, int width, int height) {
  if (mask.width == width && mask.height == height) return mask;
  splat::IdMap ids(mask.width, mask.height);
  std::copy(mask.on.begin(), mask.on.end(), ids.ids.begin());
  const splat::IdMap r = splat::resize_id_map_nearest(ids, width, height);
  Mask out(width, height);
  std::copy(r.ids.begin(), r.ids.end(), out.on.begin());
  return out;
}

double mask_iou(const Mask& gt, const Mask& pred) {
  if (gt.width != pred.width || gt.height != pred.height)
    throw std::invalid_argument("mask_iou: masks differ in size");
  size_t inter = 0, uni = 0;
  for (size_t p = 0; p < gt.on.size(); ++p) {
    inter += gt.on[p] & pred.on[p];
    uni += gt.on[p] | pred.on[p];
  }
  return uni ? double(inter) / double(uni) : std::numeric_limits<double>::quiet_NaN();
}

int boundary_width(int width, int height, double ratio) {
  const double diagonal = std::sqrt(double(height) * height + double(width) * width);
  return std::max(1, int(std::nearbyint(ratio * diagonal)));  // ties to even
}

namespace {

// out[x] = 1 where in[x - d .. x + d] are all 1 (outside counts as 0).
void erode_row(const uint8_t* in, uint8_t* out, int n, int d, std::vector<int>& prefix) {
  prefix.assign(size_t(n) + 1, 0);
  for (int i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + in[i];
  for (int i = 0; i < n; ++i) {
    const int lo = i - d, hi = i + d + 1;
    out[i] = lo >= 0 && hi <= n && prefix[hi] - prefix[lo] == 2 * d + 1;
  }
}

}  // namespace

Mask mask_boundary(const Mask& m, int d) {
  const int W = m.width, H = m.height;
  Mask rows(W, H);
  std::vector<int> prefix;
  // A square erosion is a row erosion followed by a column erosion; the
  // column one runs on column prefix sums built row by row (cache-friendly).
  for (int y = 0; y < H; ++y)
    erode_row(&m.on[size_t(y) * W], &rows.on[size_t(y) * W], W, d, prefix);
  std::vector<int> column((size_t(H) + 1) * W, 0);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      column[size_t(y + 1) * W + x] = column[size_t(y) * W + x] + rows.on[size_t(y) * W + x];
  Mask boundary(W, H);
  for (int y = 0; y < H; ++y) {
    const bool inside = y - d >= 0 && y + d + 1 <= H;
    const int* lo = inside ? &column[size_t(y - d) * W] : nullptr;
    const int* hi = inside ? &column[size_t(y + d + 1) * W] : nullptr;
    for (int x = 0; x < W; ++x) {
      const size_t p = size_t(y) * W + x;
      const bool eroded = inside && hi[x] - lo[x] == 2 * d + 1;
      boundary.on[p] = m.on[p] && !eroded;
    }
  }
  return boundary;
}

double boundary_iou(const Mask& gt, const Mask& pred, double ratio) {
  const int d = boundary_width(gt.width, gt.height, ratio);
  return mask_iou(mask_boundary(gt, d), mask_boundary(pred, d));
}

}  // namespace eval
