#include "splat/packed_id_map.h"

#include <gtest/gtest.h>

#include <random>

namespace splat {
namespace {

// A segmenter's map: a few discs of object IDs on background.
IdMap discs(int w, int h) {
  IdMap m(w, h);
  const int cx[] = {10, 40, 70}, cy[] = {12, 30, 20}, r[] = {8, 12, 6};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < 3; ++k)
        if ((x - cx[k]) * (x - cx[k]) + (y - cy[k]) * (y - cy[k]) <= r[k] * r[k])
          m.at(x, y) = uint16_t(k + 1);
  return m;
}

TEST(PackedIdMap, UnpacksToTheSameMap) {
  const IdMap m = discs(90, 50);
  const PackedIdMap p = PackedIdMap::pack(m);
  EXPECT_EQ(p.width(), 90);
  EXPECT_EQ(p.height(), 50);
  EXPECT_EQ(p.unpack().ids, m.ids);
}

TEST(PackedIdMap, ASegmentersMapTakesAFractionOfItsPixels) {
  const IdMap m = discs(90, 50);
  const PackedIdMap p = PackedIdMap::pack(m);
  EXPECT_LT(p.bytes() * 5, m.ids.size() * sizeof(uint16_t));
}

TEST(PackedIdMap, NoisyMapsAndEveryIdRoundTrip) {
  std::mt19937 rng(7);
  IdMap m(33, 17);
  for (auto& id : m.ids) id = uint16_t(rng() % 3 == 0 ? rng() : 5);
  m.ids.front() = 65535;
  m.ids.back() = 0;
  EXPECT_EQ(PackedIdMap::pack(m).unpack().ids, m.ids);
}

TEST(PackedIdMap, OneRunForAUniformMapAndNoneForAnEmptyOne) {
  IdMap uniform(20, 10);
  EXPECT_EQ(PackedIdMap::pack(uniform).runs(), 1u);
  EXPECT_EQ(PackedIdMap::pack(uniform).unpack().ids, uniform.ids);
  const PackedIdMap empty = PackedIdMap::pack(IdMap());
  EXPECT_EQ(empty.runs(), 0u);
  EXPECT_TRUE(empty.unpack().ids.empty());
}

TEST(PackedIdMap, UnpackingIntoAnotherMapsBufferOverwritesAllOfIt) {
  const IdMap a = discs(90, 50);
  IdMap b(90, 50);
  for (auto& id : b.ids) id = 9;
  IdMap out;
  PackedIdMap::pack(b).unpack_into(out);
  PackedIdMap::pack(a).unpack_into(out);
  EXPECT_EQ(out.ids, a.ids);
  EXPECT_EQ(out.width, 90);
  EXPECT_EQ(out.height, 50);
}

TEST(PackedIdMap, RejectsAMapWhosePixelsDoNotMatchItsSize) {
  IdMap bad(4, 4);
  bad.ids.pop_back();
  EXPECT_THROW(PackedIdMap::pack(bad), std::invalid_argument);
}

}  // namespace
}  // namespace splat
