#include "splat/view_cache.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <thread>

namespace splat {
namespace {

// Values that are no 8-bit code, so the cache keeps them as floats.
PackedImageRGB image_of(size_t index) {
  ImageRGB im(10, 10);  // 1200 bytes
  std::fill(im.data.begin(), im.data.end(), 0.3f);
  im.data[0] = float(index);
  return PackedImageRGB::pack(im);
}

// An 8-bit photo's values: the cache keeps its codes, a quarter of the bytes.
PackedImageRGB photo_of(size_t index) {
  ImageRGB im(10, 10);
  im.data[0] = code_value(uint8_t(index));
  return PackedImageRGB::pack(im);
}

TEST(ViewCache, HoldsAtMostTheBudget) {
  ViewCache cache(image_of, 3 * 1200);
  for (size_t i = 0; i < 100; ++i) {
    EXPECT_EQ(cache.get(i)->data[0], float(i));
    EXPECT_LE(cache.bytes_held(), 3u * 1200);
  }
  EXPECT_EQ(cache.views_held(), 3u);
  EXPECT_EQ(cache.loads(), 100u);
}

TEST(ViewCache, EvictsLeastRecentlyUsed) {
  ViewCache cache(image_of, 2 * 1200);
  cache.get(0);
  cache.get(1);
  cache.get(0);  // 1 is now the least recently used
  cache.get(2);  // evicts 1
  EXPECT_EQ(cache.loads(), 3u);
  cache.get(0);
  EXPECT_EQ(cache.loads(), 3u);
  cache.get(1);
  EXPECT_EQ(cache.loads(), 4u);
}

TEST(ViewCache, EvictedImageStaysValidForItsHolder) {
  ViewCache cache(image_of, 1200);
  auto first = cache.get(0);
  cache.get(1);
  EXPECT_EQ(first->data[0], 0.f);
}

TEST(ViewCache, OversizedViewIsReturnedButNotKept) {
  ViewCache cache(image_of, 100);
  EXPECT_EQ(cache.get(5)->data[0], 5.f);
  EXPECT_EQ(cache.views_held(), 0u);
}

TEST(ViewCache, HoldsFourTimesAsManyEightBitViews) {
  ViewCache cache(photo_of, 3 * 1200);
  for (size_t i = 0; i < 12; ++i) cache.get(i);
  EXPECT_EQ(cache.views_held(), 12u);
  EXPECT_EQ(cache.bytes_held(), 12u * 300);
  for (size_t i = 0; i < 12; ++i) EXPECT_EQ(cache.get(i)->data[0], code_value(uint8_t(i)));
  EXPECT_EQ(cache.loads(), 12u);
}

TEST(ViewCache, GetIntoWritesTheView) {
  ViewCache cache(image_of, 3 * 1200);
  ImageRGB out;
  cache.get_into(7, out);
  EXPECT_EQ(out.width, 10);
  EXPECT_EQ(out.data[0], 7.f);
  EXPECT_EQ(out.data[1], 0.3f);
}

TEST(ViewCache, ConcurrentReadersGetCorrectImages) {
  ViewCache cache(image_of, 8 * 1200);
  std::atomic<int> wrong{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (size_t i = 0; i < 500; ++i) {
        const size_t v = (i * 7 + t) % 20;
        if (cache.get(v)->data[0] != float(v)) ++wrong;
      }
    });
  for (auto& th : threads) th.join();
  EXPECT_EQ(wrong.load(), 0);
  EXPECT_LE(cache.bytes_held(), 8u * 1200);
}

}  // namespace
}  // namespace splat
