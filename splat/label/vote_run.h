#pragma once
// A whole voting run, as op2gs-vote performs it: labels for every Gaussian of
// the stage-one model from the scene's ID maps, into its output folder
// (<work>/vote/ in a work folder, splat/work_layout.h):
//
//   point_cloud.ply          the model with the label property
//   summary.json             objects found, Gaussians and views per object,
//                            background share, vote agreement
//   preview/<stem>.png       Gaussian centres coloured by label over a few
//                            training views
//   baseline/<stem>.png      the ablation's baseline label map of each test
//                            view (16-bit IDs: label of the Gaussian with the
//                            largest alpha_i T_i), and baseline_color/ to look at

#include <filesystem>
#include <string>
#include <vector>

#include "splat/label/track_ids.h"
#include "splat/label/vote.h"
#include "splat/scene.h"
#include "splat/view_split.h"

namespace splat {

struct VoteRunOptions {
  SceneOptions scene;  // the resolution of the baseline maps and previews
  SplitRule split = SplitRule::kAuto;
  // The stage-one model: a checkpoint (.ckpt) or a PLY.
  std::filesystem::path model;
  // Folder of ID maps inside the scene; "auto": the one the scene's layout
  // prefers among those present (dataset_layout.h).
  std::string id_maps = "auto";
  VoteOptions vote;
  bool allow_missing = false;  // skip training views without an ID map (with a warning)
  int preview_views = 3;
  bool baseline_maps = true;  // render the baseline label maps of the test views
  // Join the IDs a video segmenter gave one object after losing its track
  // (track_ids.h) before taking the majority. Off: the paper's plain vote.
  bool join_switched_ids = false;
  // Find the segments that cover a second object (a merge; track_ids.h) for
  // stage two to leave out: a second pass over the views.
  bool find_merges = false;
  TrackIdOptions track_ids;

  void Check() const;  // throws std::invalid_argument with a one-line message
};

struct VoteRunResult {
  size_t gaussians = 0;
  size_t views_used = 0;
  std::vector<std::string> views_skipped;
  size_t objects = 0;                 // labels other than 0 that some Gaussian got
  double background_share = 0;        // Gaussians labelled 0
  double unseen_share = 0;            // Gaussians visible in no view (labelled 0)
  double vote_agreement = 0;          // mean share of a Gaussian's votes that its label got
  std::vector<JoinedIds> joined_ids;  // with join_switched_ids
  std::vector<IdPair> id_pairs;       // the pairs it weighed
  size_t merged_segments = 0;         // with find_merges
  double seconds = 0;
};

VoteRunResult run_voting(const std::filesystem::path& scene_dir,
                         const std::filesystem::path& out_dir, const VoteRunOptions& options);

}  // namespace splat
