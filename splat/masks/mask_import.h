#pragma once
// Turns the masks a video segmenter wrote into op2gs ID maps: one map per
// image of the scene, "<image stem>.png", 0 the background, each object one
// ID in every frame, and objects.json naming the IDs (docs/own-photos.md,
// docs/inputs.md).
//
// Per-object binary masks (mask_files.h): a pixel is inside when its value is
// more than half the file's largest value (0/1 and 0/255 masks alike; any
// channel of an RGB mask). Objects get IDs 1, 2, ... in the order of their
// names. Where masks of one frame overlap, the object whose mask in that
// frame is smallest takes the pixel (ties: the lower ID): a small object
// seen in front of a large one keeps its mask, as visible-part masks (BOP's
// mask_visib, a video segmenter's) have it, and the large one loses only an
// edge it shares.
//
// Per-frame instance maps: grey values and palette indices are the IDs, as
// they are (objects.json beside them is kept); RGB colours become IDs in the
// order they first appear over the frames, black the background, named by
// their hex code.
//
// An image without masks gets an empty map of its own size, counted.

#include <filesystem>
#include <string>
#include <vector>

#include "splat/masks/mask_files.h"

namespace splat {

struct MaskImportOptions {
  std::filesystem::path masks;   // the segmenter's folder
  std::filesystem::path images;  // the scene's images/
  enum class Layout { kAuto, kPerObject, kPerFrame };
  Layout layout = Layout::kAuto;
  std::string pattern;  // per object; empty: detected
  FrameNaming frame_naming = FrameNaming::kStem;

  void Check() const;  // throws std::invalid_argument or InputError naming the folder
};

struct MaskImportResult {
  MaskLayout layout = MaskLayout::kPerFrame;
  std::string pattern;             // per object
  std::vector<std::string> names;  // names[id - 1]; empty for grey or palette maps without names
  int max_id = 0;
  size_t frames = 0;                       // maps written (one per image)
  size_t frames_without_masks = 0;         // of them, written empty
  size_t overlap_pixels = 0;               // claimed by more than one object mask
  std::vector<std::string> skipped_files;  // masks that name no image
  int bits = 8;                            // of the maps written
};

// Writes the maps and objects.json into `out` (a staging folder: the caller
// commits it).
MaskImportResult import_masks(const MaskImportOptions& options, const std::filesystem::path& out);

}  // namespace splat
