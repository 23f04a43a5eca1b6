#pragma once
// An allocator for large buffers that are read at random, such as the
// rasterizer's per-Gaussian records: it asks the kernel to back them with
// 2 MiB pages (madvise MADV_HUGEPAGE, honoured where transparent huge pages
// are "always" or "madvise"), so random reads miss the TLB far less often.
// Buffers under 2 MiB get ordinary memory.
//
//   std::vector<SplatRecord, HugePageAllocator<SplatRecord>> records;

#include <sys/mman.h>

#include <cstddef>
#include <cstdlib>
#include <new>

namespace splat {

template <typename T>
struct HugePageAllocator {
  using value_type = T;
  static constexpr size_t kHugePage = size_t(2) << 20;

  HugePageAllocator() = default;
  template <typename U>
  HugePageAllocator(const HugePageAllocator<U>&) {}

  T* allocate(size_t n) {
    const size_t bytes = n * sizeof(T);
    if (bytes < kHugePage)
      return static_cast<T*>(::operator new(bytes, std::align_val_t(alignof(T))));
    const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* p = std::aligned_alloc(kHugePage, rounded);
    if (!p) throw std::bad_alloc();
    madvise(p, rounded, MADV_HUGEPAGE);  // a hint: without it, ordinary pages
    return static_cast<T*>(p);
  }
  void deallocate(T* p, size_t n) {
    if (n * sizeof(T) < kHugePage)
      ::operator delete(p, std::align_val_t(alignof(T)));
    else
      std::free(p);
  }

  template <typename U>
  bool operator==(const HugePageAllocator<U>&) const {
    return true;
  }
};

}  // namespace splat
