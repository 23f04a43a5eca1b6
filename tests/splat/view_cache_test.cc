#include "splat/view_cache.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <numeric>
#include <stdexcept>
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

TEST(ViewCache, PackedViewUnpacksIntoABuffer) {
  ViewCache cache(image_of, 3 * 1200);
  ImageRGB out;
  cache.packed(7)->unpack_into(out);
  EXPECT_EQ(out.width, 10);
  EXPECT_EQ(out.data[0], 7.f);
  EXPECT_EQ(out.data[1], 0.3f);
}

TEST(ViewCache, PreloadDecodesEachViewOnceAndThenServesIt) {
  ViewCache cache(image_of, 8 * 1200);
  EXPECT_EQ(cache.preload({0, 1, 2, 3, 4}), 5u);
  EXPECT_EQ(cache.loads(), 5u);
  EXPECT_EQ(cache.preload({2, 3, 4, 5}), 4u);  // only 5 is new
  EXPECT_EQ(cache.loads(), 6u);
  for (size_t i = 0; i < 6; ++i) EXPECT_EQ(cache.get(i)->data[0], float(i));
  EXPECT_EQ(cache.loads(), 6u);
}

TEST(ViewCache, PreloadStopsWhenTheCacheIsFull) {
  ViewCache cache(image_of, 3 * 1200);
  std::vector<size_t> views(100);
  std::iota(views.begin(), views.end(), size_t(0));
  const size_t held = cache.preload(views);
  EXPECT_LE(held, 3u);
  EXPECT_GE(held, 2u);  // a view decoded in parallel with the one that fills it may evict one
  EXPECT_LE(cache.bytes_held(), 3u * 1200);
  // No view starts decoding once the cache is full: at most one a thread beyond.
  EXPECT_LE(cache.loads(), 3u + size_t(tbb::this_task_arena::max_concurrency()));
}

TEST(ViewCache, PreloadPassesOnTheLoadersError) {
  ViewCache cache(
      [](size_t i) -> PackedImageRGB {
        if (i == 3) throw std::runtime_error("view 3 is unreadable");
        return image_of(i);
      },
      8 * 1200);
  EXPECT_THROW(cache.preload({0, 1, 2, 3}), std::runtime_error);
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
