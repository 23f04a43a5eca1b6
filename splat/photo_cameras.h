#pragma once
// The cameras of the user's photos, which op2gs-sfm records in
// <scene>/photo_cameras/ when it undistorts them. Renders are made in the
// undistorted pinhole views; these cameras take a render back into the
// geometry of the photo it stands for, to score it against ground truth drawn
// on the photos or to lay a mask over the photo itself.

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "splat/colmap_model.h"

namespace splat {

// The folder of a scene that records the photos' cameras.
inline constexpr char kPhotoCamerasDir[] = "photo_cameras";

class PhotoCameras {
 public:
  // Empty when the scene has no photo_cameras/ (its photos are its views).
  static PhotoCameras load(const std::filesystem::path& scene);

  bool empty() const { return photo_.empty(); }

  // A render of a view, at any size with the view's aspect ratio, sampled
  // into the photo: for every photo pixel (row-major), the index of the
  // nearest render pixel, or -1 where the view cropped the photo away.
  struct Sampling {
    int width = 0, height = 0;  // the photo's
    std::vector<int64_t> sources;

    // The photo's pixels taken from a render's (row-major), `outside` where
    // the view cropped the photo away.
    template <typename T>
    std::vector<T> gather(std::span<const T> render, T outside = T{}) const {
      std::vector<T> photo(sources.size(), outside);
      for (size_t i = 0; i < sources.size(); ++i)
        if (sources[i] >= 0) photo[i] = render[size_t(sources[i])];
      return photo;
    }
  };
  // nullopt when the view with this image name is not in both models.
  std::optional<Sampling> sampling(const std::string& image_name, int render_width,
                                   int render_height) const;

 private:
  std::map<std::string, ColmapCamera> photo_, view_;  // by image name
};

}  // namespace splat
