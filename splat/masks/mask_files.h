#pragma once
// Where a segmenter's masks sit in a folder, and which object and which
// frame each file holds (docs/own-photos.md). Two layouts:
//
//   per object  one binary mask per object per frame, found by a file-name
//               pattern relative to the folder:
//                 "{object}/{frame}.png"       SAM2's video predictor, saved
//                                              a folder per object
//                 "{frame}_{object}.png"       BOP's mask_visib/
//                 "{*}_{object}_{frame}.png"   Tracebot: scene, object and
//                                              instance, frame
//   per frame   one instance map per frame, "<frame>.png": grey IDs (DEVA,
//               Gaussian Grouping's object_mask/), palette indices (SAM2's
//               vos_inference.py, DAVIS) or RGB colours.
//
// A frame is an image of the scene's images/ folder, named by its stem; a
// number matches the image whose stem is the same number ("7" and "00007").

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace splat {

enum class MaskLayout { kPerObject, kPerFrame };

// One file of the per-object layout.
struct ObjectMaskFile {
  std::string object;  // what {object} matched
  std::string frame;   // the image stem that {frame} matched
  std::filesystem::path path;
};

// How a mask file's frame token names an image:
//   kStem   the image's stem, or the same number ("7" and "00007");
//   kIndex  the image's position, from 0, in images/ sorted by name: SAM2's
//           video predictor reads a folder of frames named <index>.jpg and
//           numbers its masks so, when the photos themselves are not numbered.
enum class FrameNaming { kStem, kIndex };

// The image stem a frame token names among `stems` (sorted). Nothing when
// none, or (kStem) several, match.
std::optional<std::string> match_frame(const std::string& token,
                                       const std::vector<std::string>& stems,
                                       FrameNaming naming = FrameNaming::kStem);

// The PNG files under `folder` (relative paths with '/', sorted).
std::vector<std::string> list_mask_files(const std::filesystem::path& folder);

// Matches a pattern against relative paths. Placeholders: {object} (kept as
// the object's name), {frame} (an image stem), {*} (anything, not kept); the
// rest is literal. Throws std::invalid_argument when the pattern lacks
// {object} or {frame}.
class MaskPattern {
 public:
  explicit MaskPattern(const std::string& pattern);
  // {object, frame token} of a path that matches; nothing otherwise.
  std::optional<std::pair<std::string, std::string>> match(const std::string& path) const;
  const std::string& text() const { return text_; }

 private:
  std::string text_;
  std::string regex_;
  int object_group_ = 0, frame_group_ = 0;
};

// What the files under `folder` look like: per frame when every PNG directly
// in it is named after an image; else per object, by the first of the three
// patterns above that names an image in most of the files. Throws
// InputError naming the folder when it holds no PNG or none of them fits.
struct DetectedMasks {
  MaskLayout layout = MaskLayout::kPerFrame;
  std::string pattern;  // per object only
};
DetectedMasks detect_mask_layout(const std::filesystem::path& folder,
                                 const std::vector<std::string>& stems,
                                 FrameNaming naming = FrameNaming::kStem);

// The per-object files under `folder` that `pattern` matches and whose frame
// is an image; `skipped` receives the files that match no image.
std::vector<ObjectMaskFile> find_object_masks(const std::filesystem::path& folder,
                                              const MaskPattern& pattern,
                                              const std::vector<std::string>& stems,
                                              FrameNaming naming,
                                              std::vector<std::string>& skipped);

}  // namespace splat
