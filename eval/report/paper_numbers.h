#pragma once
// The published figures of the OP2GS paper (Liu et al., "OP2GS: Object-Aware
// 3D Gaussian Primitives via Dual Opacity": its LERF-Mask, 3DOVS and ablation tables), for the
// reports to put beside ours. In percent.

#include <optional>
#include <string>
#include <vector>

namespace eval {

enum class Dataset { kOther, kLerfMask, kOvs };

// "lerf-mask" / "3dovs" / anything else.
Dataset dataset_named(const std::string& name);
std::string dataset_title(Dataset d);
// A dataset whose scenes are all named as one of the paper's datasets.
Dataset dataset_of_scenes(const std::vector<std::string>& scene_names);

struct PaperSceneFigure {
  double miou = 0;
  std::optional<double> mbiou;  // the 3DOVS tables give mIoU only
};

// The pseudo-labels a run voted and learned from: the paper reports both
// (its appendix, "SAM2 and SAM+DEVA").
enum class PseudoLabels { kSam2, kSamDeva };
// From the ID map folder a run used: DEVA's as LERF-Mask ships it
// (object_mask/) and as ObjectGS prepares 3DOVS (object_mask_deva/), SAM2's
// otherwise (sam2/, and the user's own).
PseudoLabels pseudo_labels_of_folder(const std::string& id_map_folder);
std::string pseudo_labels_name(PseudoLabels p);  // "SAM2", "SAM+DEVA"

// The paper's per-scene result with those pseudo-labels (table "LERF-Mask"
// and its appendix's SAM+DEVA row, or the 3DOVS tables of the main text and
// the appendix), if it has one.
std::optional<PaperSceneFigure> paper_scene_figure(Dataset d, const std::string& scene,
                                                   PseudoLabels labels = PseudoLabels::kSam2);

// The paper's ablation table ("dual-opacity in two stages"): mIoU and mBIoU
// of the baseline and of dual opacity, in oracle and query mode.
struct PaperAblationRow {
  std::string mode;  // "oracle" or "query"
  double baseline_miou, baseline_mbiou, dual_miou, dual_mbiou;
};
std::vector<PaperAblationRow> paper_ablation(Dataset d);

}  // namespace eval
