// op2gs-masks: the masks a video segmenter wrote (SAM2, DEVA, BOP-style
// per-object masks, colour-coded instance maps) as the ID maps the stages
// read, <scene>/sam2/ by default (docs/own-photos.md).

#include "splat/masks/mask_import.h"
#include "stages/common.h"

int main(int argc, char** argv) {
  CLI::App app{"Turn a segmenter's masks into op2gs ID maps, one per image of the scene."};
  splat::MaskImportOptions o;
  std::string masks, scene, out, layout = "auto";
  app.add_option("masks", masks, "the segmenter's folder of masks")->required();
  app.add_option("scene", scene, "scene folder (images/)")->required();
  app.add_option("--out", out, "ID map folder to write (default <scene>/sam2)");
  app.add_option("--layout", layout,
                 "auto, per-object (one binary mask per object per frame) or per-frame (one "
                 "instance map per frame: grey IDs, palette indices or RGB colours)")
      ->capture_default_str();
  app.add_option("--pattern", o.pattern,
                 "per-object file names relative to the folder, with {object}, {frame} (an "
                 "image stem or its number) and {*} (anything): \"{object}/{frame}.png\" "
                 "(SAM2), \"{frame}_{object}.png\" (BOP mask_visib), \"{*}_{object}_{frame}.png\" "
                 "(Tracebot); default: detected");
  bool frame_index = false;
  app.add_flag("--frame-index", frame_index,
               "the masks' frame numbers are positions, from 0, in images/ sorted by name (SAM2's "
               "video predictor numbers the frames of its folder so), not the images' own names");
  return stages::run_stage(app, argc, argv, [&] {
    o.frame_naming = frame_index ? splat::FrameNaming::kIndex : splat::FrameNaming::kStem;
    o.masks = masks;
    o.images = std::filesystem::path(scene) / "images";
    o.layout = stages::parse_choice<splat::MaskImportOptions::Layout>(
        "--layout", layout,
        {{"auto", splat::MaskImportOptions::Layout::kAuto},
         {"per-object", splat::MaskImportOptions::Layout::kPerObject},
         {"per-frame", splat::MaskImportOptions::Layout::kPerFrame}});
    o.Check();
    const std::filesystem::path target =
        out.empty() ? std::filesystem::path(scene) / "sam2" : std::filesystem::path(out);
    if (std::filesystem::exists(target) && std::filesystem::equivalent(target, o.masks))
      throw splat::InputError(target,
                              "is the masks' own folder: write the ID maps to another "
                              "(--out)");
    splat::StagedFolder staged(target, splat::StagedFolder::Target::kShared);
    const splat::MaskImportResult r = splat::import_masks(o, staged.path());
    staged.commit();
    if (r.layout == splat::MaskLayout::kPerObject)
      spdlog::info("per-object masks, pattern \"{}\": {} objects", r.pattern, r.names.size());
    else
      spdlog::info("per-frame instance maps: IDs up to {}{}", r.max_id,
                   r.names.empty() ? "" : fmt::format(", {} colours named", r.names.size()));
    for (size_t i = 0; i < r.names.size() && i < 50; ++i)
      spdlog::info("  {:5d}  {}", i + 1, r.names[i]);
    if (r.overlap_pixels > 0)
      spdlog::info("{} pixels claimed by several objects went to the smallest mask",
                   r.overlap_pixels);
    if (!r.skipped_files.empty())
      spdlog::warn("{} mask files name no image of {} and were skipped (first: {})",
                   r.skipped_files.size(), o.images.string(), r.skipped_files.front());
    if (r.frames_without_masks > 0)
      spdlog::warn("{} of {} images have no mask: written as background only",
                   r.frames_without_masks, r.frames);
    spdlog::info("{} {}-bit ID maps in {}", r.frames, r.bits, target.string());
  });
}
