#pragma once
// An allocator for large buffers that are read at random, such as the
// rasterizer's per-Gaussian records: it asks the kernel to back them with
// 2 MiB pages (madvise MADV_HUGEPAGE, honoured where transparent huge pages
// are "always" or "madvise"), so random reads miss the TLB far less often.
// Buffers under 2 MiB get ordinary memory, aligned to a cache line.
//
//   std::vector<SplatRecord, HugePageAllocator<SplatRecord>> records;
//
// ImageBuffer<T> is the renderer's output image type: the same memory, and
// resize() leaves new elements unset (default-initialised), because the
// renderer writes every element of its outputs; a value-initialising resize
// would first clear the whole image each time a buffer grows back.

#include <sys/mman.h>

#include <cstddef>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace splat {

template <typename T>
struct HugePageAllocator {
  using value_type = T;
  static constexpr size_t kHugePage = size_t(2) << 20;
  static constexpr size_t kSmallAlignment = alignof(T) > 64 ? alignof(T) : 64;

  HugePageAllocator() = default;
  template <typename U>
  HugePageAllocator(const HugePageAllocator<U>&) {}

  T* allocate(size_t n) {
    const size_t bytes = n * sizeof(T);
    if (bytes < kHugePage)
      return static_cast<T*>(::operator new(bytes, std::align_val_t(kSmallAlignment)));
    const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* p = std::aligned_alloc(kHugePage, rounded);
    if (!p) throw std::bad_alloc();
    madvise(p, rounded, MADV_HUGEPAGE);  // a hint: without it, ordinary pages
    return static_cast<T*>(p);
  }
  void deallocate(T* p, size_t n) {
    if (n * sizeof(T) < kHugePage)
      ::operator delete(p, std::align_val_t(kSmallAlignment));
    else
      std::free(p);
  }

  template <typename U>
  bool operator==(const HugePageAllocator<U>&) const {
    return true;
  }
};

// A HugePageAllocator whose construct() without arguments default-initialises.
template <typename T>
struct DefaultInitAllocator : HugePageAllocator<T> {
  template <typename U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() = default;
  template <typename U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) {}

  template <typename U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

template <typename T>
using ImageBuffer = std::vector<T, DefaultInitAllocator<T>>;

}  // namespace splat
