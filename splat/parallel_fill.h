#pragma once
// Resizing and filling the large per-Gaussian arrays in parallel: a serial
// std::vector::assign of a million Gaussians' gradients is tens of MB of
// memset on one thread every iteration, and the thread that first touches a
// page decides its NUMA node.

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace splat {

// v.size() becomes n and every element `value`.
template <typename T, typename Allocator>
void parallel_assign(std::vector<T, Allocator>& v, size_t n, const T& value) {
  v.resize(n);
  constexpr size_t kGrain = size_t(1) << 16;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain), [&](const auto& r) {
    std::fill(v.begin() + std::ptrdiff_t(r.begin()), v.begin() + std::ptrdiff_t(r.end()), value);
  });
}

}  // namespace splat
