#include "synth/mask_errors_run.h"

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/id_maps.h"

namespace synth {
namespace fs = std::filesystem;

void MaskErrorRunOptions::Check() const {
  sam2.Check();
  tracks.Check();
}

namespace {

// Intersection over union of one ID's pixels in two maps, or -1 when neither has it.
double object_iou(const splat::IdMap& a, const splat::IdMap& b, int id) {
  size_t inter = 0, uni = 0;
  for (size_t i = 0; i < a.ids.size(); ++i) {
    const bool x = a.ids[i] == id, y = b.ids[i] == id;
    inter += x && y;
    uni += x || y;
  }
  return uni == 0 ? -1 : double(inter) / double(uni);
}

}  // namespace

MaskErrorRunResult add_mask_errors(const fs::path& in, const fs::path& out,
                                   const MaskErrorRunOptions& o) {
  o.Check();
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(in))
    if (e.is_regular_file() && e.path().extension() == ".png") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw splat::InputError(in, "holds no ID maps (*.png)");

  std::vector<splat::IdMap> truth;
  std::set<int> ids;
  for (const auto& f : files) {
    truth.push_back(splat::read_id_map(f));
    for (int id : splat::ids_in_map(truth.back()))
      if (id) ids.insert(id);
  }
  const std::vector<int> object_ids(ids.begin(), ids.end());
  std::vector<splat::IdMap> maps = corrupt_sequence_like_sam2(truth, object_ids, o.sam2, o.seed);
  const std::vector<int> new_ids =
      apply_track_errors(maps, truth, object_ids, o.tracks, o.seed * 7919 + 1);

  MaskErrorRunResult r;
  r.maps = files.size();
  r.objects = object_ids.size();
  r.new_ids = new_ids.size();
  size_t changed = 0, pixels = 0, scored = 0;
  double iou_sum = 0;
  int largest = 0;
  for (size_t v = 0; v < maps.size(); ++v) {
    for (size_t i = 0; i < maps[v].ids.size(); ++i) changed += maps[v].ids[i] != truth[v].ids[i];
    pixels += maps[v].ids.size();
    for (int id : object_ids) {
      const double iou = object_iou(truth[v], maps[v], id);
      if (iou >= 0) iou_sum += iou, ++scored;
    }
    for (uint16_t id : maps[v].ids) largest = std::max<int>(largest, id);
  }
  r.changed_share = double(changed) / double(std::max<size_t>(pixels, 1));
  r.mean_object_iou = scored ? iou_sum / double(scored) : 1.0;
  for (size_t v = 0; v < maps.size(); ++v)
    splat::write_id_map(out / files[v].filename(), maps[v], largest > 255 ? 16 : 8);

  // The names stay those of the exact maps; the new IDs of switched tracks
  // have none, as a segmenter would not know them.
  if (fs::is_regular_file(in / "objects.json"))
    splat::write_text_atomically(out / "objects.json", splat::read_text_file(in / "objects.json"));
  return r;
}

}  // namespace synth
