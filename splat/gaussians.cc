#include "splat/gaussians.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <stdexcept>

namespace splat {

void GaussianModel::resize(size_t n) {
  const size_t old = size();
  means.resize(3 * n, 0.f);
  sh_dc.resize(3 * n, 0.f);
  sh_rest.resize(kShRestFloats * n, 0.f);
  opacity_logits.resize(n, 0.f);
  log_scales.resize(3 * n, 0.f);
  rotations.resize(4 * n, 0.f);
  for (size_t i = old; i < n; ++i) rotations[4 * i] = 1.f;
  instance_opacity_logits.resize(n, 0.f);
  labels.resize(n, 0);
}

namespace {

// 10 bits of x, y and z interleaved.
uint32_t morton_code(uint32_t x, uint32_t y, uint32_t z) {
  auto spread = [](uint32_t v) {
    v = (v | (v << 16)) & 0x030000FF;
    v = (v | (v << 8)) & 0x0300F00F;
    v = (v | (v << 4)) & 0x030C30C3;
    v = (v | (v << 2)) & 0x09249249;
    return v;
  };
  return spread(x) | (spread(y) << 1) | (spread(z) << 2);
}

}  // namespace

template <typename T>
void reorder_array(std::vector<T>& values, size_t width, const std::vector<uint32_t>& order) {
  if (values.empty()) return;
  std::vector<T> out(values.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, order.size(), 16384), [&](const auto& range) {
    for (size_t k = range.begin(); k < range.end(); ++k)
      std::copy_n(&values[width * order[k]], width, &out[width * k]);
  });
  values.swap(out);
}
template void reorder_array(std::vector<float>&, size_t, const std::vector<uint32_t>&);
template void reorder_array(std::vector<int32_t>&, size_t, const std::vector<uint32_t>&);
template void reorder_array(std::vector<double>&, size_t, const std::vector<uint32_t>&);

void reorder_gaussians(GaussianModel& m, const std::vector<uint32_t>& order) {
  if (order.size() != m.size()) throw std::invalid_argument("reorder: order has the wrong size");
  reorder_array(m.means, 3, order);
  reorder_array(m.sh_dc, 3, order);
  reorder_array(m.sh_rest, kShRestFloats, order);
  reorder_array(m.opacity_logits, 1, order);
  reorder_array(m.log_scales, 3, order);
  reorder_array(m.rotations, 4, order);
  reorder_array(m.instance_opacity_logits, 1, order);
  reorder_array(m.labels, 1, order);
}

std::vector<uint32_t> spatial_order(const GaussianModel& m) {
  const size_t n = m.size();
  std::vector<uint32_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = uint32_t(i);
  if (n < 2) return order;
  // The box: all but the farthest 0.1% on each side of each axis, so that a
  // few far floaters do not squeeze the scene into a handful of cells.
  float lo[3], scale[3];
  std::vector<float> axis(n);
  for (int a = 0; a < 3; ++a) {
    for (size_t i = 0; i < n; ++i) axis[i] = m.means[3 * i + a];
    const size_t cut = n / 1000;
    std::nth_element(axis.begin(), axis.begin() + cut, axis.end());
    lo[a] = axis[cut];
    std::nth_element(axis.begin(), axis.begin() + (n - 1 - cut), axis.end());
    const float hi = axis[n - 1 - cut];
    scale[a] = hi > lo[a] ? 1023.f / (hi - lo[a]) : 0.f;
  }
  std::vector<uint64_t> keys(n);  // code << 32 | index: ties keep the model's order
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 16384), [&](const auto& range) {
    for (size_t i = range.begin(); i < range.end(); ++i) {
      uint32_t cell[3];
      for (int a = 0; a < 3; ++a) {
        const float v = (m.means[3 * i + a] - lo[a]) * scale[a];
        cell[a] = v > 0.f ? uint32_t(std::min(v, 1023.f)) : 0u;  // NaN: 0
      }
      keys[i] = uint64_t(morton_code(cell[0], cell[1], cell[2])) << 32 | i;
    }
  });
  tbb::parallel_sort(keys.begin(), keys.end());
  for (size_t k = 0; k < n; ++k) order[k] = uint32_t(keys[k]);
  return order;
}

std::vector<uint32_t> inverse_order(const std::vector<uint32_t>& order) {
  std::vector<uint32_t> inverse(order.size());
  for (size_t k = 0; k < order.size(); ++k) inverse[order[k]] = uint32_t(k);
  return inverse;
}

const char* group_name(ParamGroup g) {
  static const char* names[] = {"means",  "sh_dc",     "sh_rest",         "opacity",
                                "scales", "rotations", "instance_opacity"};
  return names[int(g)];
}

int group_width(ParamGroup g) {
  static const int widths[] = {3, 3, kShRestFloats, 1, 3, 4, 1};
  return widths[int(g)];
}

std::vector<float>& group_values(GaussianModel& m, ParamGroup g) {
  switch (g) {
    case ParamGroup::kMeans:
      return m.means;
    case ParamGroup::kShDc:
      return m.sh_dc;
    case ParamGroup::kShRest:
      return m.sh_rest;
    case ParamGroup::kOpacity:
      return m.opacity_logits;
    case ParamGroup::kScales:
      return m.log_scales;
    case ParamGroup::kRotations:
      return m.rotations;
    case ParamGroup::kInstanceOpacity:
      return m.instance_opacity_logits;
  }
  throw std::logic_error("bad group");
}

const std::vector<float>& group_values(const GaussianModel& m, ParamGroup g) {
  return group_values(const_cast<GaussianModel&>(m), g);
}

void keep_gaussians(GaussianModel& m, const std::vector<uint8_t>& keep) {
  for (int g = 0; g < kParamGroups; ++g)
    keep_entries(group_values(m, ParamGroup(g)), size_t(group_width(ParamGroup(g))), keep);
  keep_entries(m.labels, 1, keep);
}

}  // namespace splat
