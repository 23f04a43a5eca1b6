#include "splat/huge_page_allocator.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <vector>

namespace splat {
namespace {

struct alignas(64) Record {
  float values[16];
};

TEST(HugePageAllocator, LargeBuffersStartOnA2MiBBoundary) {
  std::vector<Record, HugePageAllocator<Record>> records(100000);  // 6.4 MB
  EXPECT_EQ(reinterpret_cast<uintptr_t>(records.data()) % HugePageAllocator<Record>::kHugePage, 0u);
  for (size_t i = 0; i < records.size(); ++i) records[i].values[15] = float(i);
  EXPECT_EQ(records.back().values[15], 99999.f);
}

TEST(HugePageAllocator, SmallBuffersKeepTheirAlignmentAndGrow) {
  std::vector<Record, HugePageAllocator<Record>> records(3);
  EXPECT_EQ(reinterpret_cast<uintptr_t>(records.data()) % alignof(Record), 0u);
  // Growing across the 2 MiB threshold moves the data into a large buffer.
  for (int i = 0; i < 40000; ++i) records.push_back(Record{{float(i)}});
  EXPECT_EQ(records[3 + 39999].values[0], 39999.f);
  std::vector<int, HugePageAllocator<int>> ints(1 << 20);
  std::iota(ints.begin(), ints.end(), 0);
  EXPECT_EQ(ints[123456], 123456);
}

TEST(ImageBuffer, IsCacheLineAlignedAtEverySize) {
  // The renderer writes whole aligned cache lines of its outputs with
  // streaming stores; a misaligned buffer would silently lose that.
  for (size_t n : {size_t(1), size_t(1000), size_t(3) << 20}) {
    ImageBuffer<float> image(n);
    EXPECT_EQ(reinterpret_cast<uintptr_t>(image.data()) % 64, 0u) << n;
  }
}

TEST(ImageBuffer, KeepsValuesItIsGiven) {
  ImageBuffer<float> image(5, 2.5f);
  image.resize(8, 1.f);
  EXPECT_EQ(image, (ImageBuffer<float>{2.5f, 2.5f, 2.5f, 2.5f, 2.5f, 1.f, 1.f, 1.f}));
}

}  // namespace
}  // namespace splat
