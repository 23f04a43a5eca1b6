#pragma once
// An ID map as stage two keeps it for the whole run: its runs of equal IDs
// in raster order. Stage two holds every training view's map so that no
// iteration waits on a decode; as 16-bit pixels the 262 maps of a
// LERF-Mask-size scene take 376 MB, more than stage two's other additions
// to stage one, while a segmenter's map is a few regions per row: as runs
// they take about a hundredth of that (stage two's peak fell by 355 MiB,
// docs/benchmarks.md). Unpacking gives the map back exactly.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "splat/image.h"

namespace splat {

class PackedIdMap {
 public:
  static PackedIdMap pack(const IdMap& map);

  int width() const { return width_; }
  int height() const { return height_; }
  size_t runs() const { return ids_.size(); }
  size_t bytes() const { return ids_.size() * sizeof(uint16_t) + ends_.size() * sizeof(uint32_t); }

  // Writes the map into `out`, resizing it; a buffer reused across calls is
  // not reallocated.
  void unpack_into(IdMap& out) const;
  IdMap unpack() const;

 private:
  int width_ = 0, height_ = 0;
  std::vector<uint16_t> ids_;   // the ID of each run
  std::vector<uint32_t> ends_;  // the pixel index one past each run's last
};

}  // namespace splat
