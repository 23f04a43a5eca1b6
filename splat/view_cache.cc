#include "splat/view_cache.h"

#include <tbb/parallel_for.h>

#include <algorithm>

namespace splat {

ViewCache::ViewCache(Loader loader, size_t max_bytes)
    : loader_(std::move(loader)), max_bytes_(max_bytes) {}

std::shared_ptr<const ImageRGB> ViewCache::get(size_t index) {
  return std::make_shared<const ImageRGB>(packed(index)->unpack());
}

size_t ViewCache::preload(const std::vector<size_t>& indices) {
  // One view a task: a decode is long, and the views' sizes may differ.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, indices.size(), 1), [&](const auto& range) {
    for (size_t k = range.begin(); k < range.end(); ++k) {
      {
        std::lock_guard lock(mutex_);
        if (bytes_ >= max_bytes_ || entries_.count(indices[k])) continue;
      }
      packed(indices[k]);
    }
  });
  std::lock_guard lock(mutex_);
  return size_t(std::count_if(indices.begin(), indices.end(),
                              [&](size_t i) { return entries_.count(i) > 0; }));
}

std::shared_ptr<const PackedImageRGB> ViewCache::packed(size_t index) {
  {
    std::lock_guard lock(mutex_);
    if (auto it = entries_.find(index); it != entries_.end()) {
      lru_.splice(lru_.begin(), lru_, it->second.position);
      return it->second.image;
    }
  }
  // Decode outside the lock so other threads can use cached views meanwhile.
  auto image = std::make_shared<const PackedImageRGB>(loader_(index));
  std::lock_guard lock(mutex_);
  ++loads_;
  if (auto it = entries_.find(index); it != entries_.end()) return it->second.image;
  if (image->bytes() > max_bytes_) return image;
  lru_.push_front(index);
  entries_[index] = Entry{image, lru_.begin()};
  bytes_ += image->bytes();
  evict_to_fit_locked();
  return image;
}

void ViewCache::evict_to_fit_locked() {
  while (bytes_ > max_bytes_ && !lru_.empty()) {
    const size_t victim = lru_.back();
    lru_.pop_back();
    bytes_ -= entries_[victim].image->bytes();
    entries_.erase(victim);
  }
}

size_t ViewCache::bytes_held() const {
  std::lock_guard lock(mutex_);
  return bytes_;
}
size_t ViewCache::views_held() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}
size_t ViewCache::loads() const {
  std::lock_guard lock(mutex_);
  return loads_;
}

}  // namespace splat
