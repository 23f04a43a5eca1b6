#pragma once
// A bounded, thread-safe, least-recently-used cache of decoded views, so that
// a scene of thousands of views never needs all of them in memory at once.
// Views are held packed (packed_image.h): 8-bit photos as their codes, a
// quarter of their decoded floats.

#include <cstddef>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <vector>

#include "splat/image.h"
#include "splat/packed_image.h"

namespace splat {

class ViewCache {
 public:
  using Loader = std::function<PackedImageRGB(size_t index)>;

  // max_bytes bounds the packed pixels held; one view larger than the bound
  // is still returned, just not kept.
  ViewCache(Loader loader, size_t max_bytes);

  // The image of view `index`, loaded on a miss, as a new image of its own.
  std::shared_ptr<const ImageRGB> get(size_t index);
  // The view as the cache holds it, loaded and inserted on a miss: a caller
  // reads a view held as floats in place (PackedImageRGB::floats), the
  // pointer keeping it alive should the cache drop it meanwhile.
  std::shared_ptr<const PackedImageRGB> packed(size_t index);
  // Decodes the views not yet held, on all cores, in the order given, until
  // the cache is full: a trainer that visits every view calls it once before
  // its first iteration, so no iteration waits on a decode (OpenSplat and
  // the 3DGS reference load every photo up front too). Returns how many of
  // the views are held afterwards.
  size_t preload(const std::vector<size_t>& indices);

  size_t bytes_held() const;
  size_t views_held() const;
  size_t loads() const;  // number of decodes so far (misses)
  size_t max_bytes() const { return max_bytes_; }

 private:
  void evict_to_fit_locked();

  Loader loader_;
  size_t max_bytes_;
  mutable std::mutex mutex_;
  std::list<size_t> lru_;  // front = most recently used
  struct Entry {
    std::shared_ptr<const PackedImageRGB> image;
    std::list<size_t>::iterator position;
  };
  std::unordered_map<size_t, Entry> entries_;
  size_t bytes_ = 0;
  size_t loads_ = 0;
};

}  // namespace splat
