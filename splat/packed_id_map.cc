#include "splat/packed_id_map.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace splat {

PackedIdMap PackedIdMap::pack(const IdMap& map) {
  const size_t n = map.ids.size();
  if (n != size_t(map.width) * size_t(map.height))
    throw std::invalid_argument("PackedIdMap::pack: the map's size is not width * height");
  if (n > std::numeric_limits<uint32_t>::max())
    throw std::invalid_argument("PackedIdMap::pack: more than 2^32 pixels");
  PackedIdMap p;
  p.width_ = map.width;
  p.height_ = map.height;
  for (size_t i = 0; i < n;) {
    const uint16_t id = map.ids[i];
    size_t end = i + 1;
    while (end < n && map.ids[end] == id) ++end;
    p.ids_.push_back(id);
    p.ends_.push_back(uint32_t(end));
    i = end;
  }
  p.ids_.shrink_to_fit();
  p.ends_.shrink_to_fit();
  return p;
}

void PackedIdMap::unpack_into(IdMap& out) const {
  out.width = width_;
  out.height = height_;
  out.ids.resize(size_t(width_) * size_t(height_));
  uint32_t begin = 0;
  for (size_t r = 0; r < ids_.size(); ++r) {
    std::fill(out.ids.begin() + begin, out.ids.begin() + ends_[r], ids_[r]);
    begin = ends_[r];
  }
}

IdMap PackedIdMap::unpack() const {
  IdMap out;
  unpack_into(out);
  return out;
}

}  // namespace splat
