#pragma once
// The random object loss of stage two (paper, "Random Object Loss"): for M
// object IDs sampled among those the view's ID map shows, the binary
// cross-entropy between the occupancy map S_j and the binary mask B_j over
// all pixels, averaged over the M objects:
//
//   L_obj = 1/M sum_j  mean_v  -[B_j log S_j + (1 - B_j) log(1 - S_j)].

#include <cstdint>
#include <filesystem>
#include <map>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "splat/image.h"

namespace splat {

// The loss of one pixel of one object's map, p being the occupancy's
// probability of the mask's value there (S where B = 1, 1 - S where B = 0):
//
//   kCrossEntropy  -log p, the paper's binary cross-entropy;
//   kGeneralized   (1 - p^q) / q, the generalized cross-entropy of Zhang and
//                  Sabuncu (NeurIPS 2018), q in (0, 1]: -log p as q -> 0,
//                  the mean absolute error 1 - p at q = 1.
//
// Why the second: sigma* is regressed on every view's mask, and under the
// cross-entropy a pixel whose masks say "inside" in a share r of the views
// settles at S = r (the mean), so the views whose mask missed a part, or
// leaked, pull it with them. Its gradient, p^(q-1) instead of 1/p, grows
// less where the model disagrees with a mask; with q = 0.7 (the paper's
// choice for noisy labels) the same pixel settles at
// S / (1 - S) = (r / (1 - r))^(1 / (1 - q)): 3 of 4 views "inside" gives
// S = 0.97, not 0.75, close to the majority that the vote also takes. With
// exact masks (r = 0 or 1) both settle at B.
//
// Why the cross-entropy near the model's outline (outline_band): with the
// generalized loss everywhere the masks come out dilated on the synthetic
// scenes (more false positives, fewer false negatives than with the
// cross-entropy, most of them within 3 pixels of the true outline). The
// loss ignores a minority of pixels that disagree with the model, which is
// how it outvotes a view's miss deep inside an object, and the tail of a
// Gaussian on the object's border, reaching a pixel or two past the
// outline, is such a minority of its pixels too. Along the outline the
// masks' error is a jitter of a few pixels whatever the object's size
// (docs/synthetic.md), which the cross-entropy averages without a bias. So
// within outline_band pixels of the outline of the model's own mask of the
// object (S_j >= mask_threshold, as the rendered masks) the loss is the
// cross-entropy, and elsewhere the generalized loss outvotes the misses and
// leaks. The model's outline, not the view's mask's: a mask's outline runs
// around its own errors too (a missed blob, a leak), and a band there kept
// the cross-entropy's pull on the holes (measured: Tracebot 001, the false
// negatives away from the true outline).
struct PixelLoss {
  enum class Kind { kCrossEntropy, kGeneralized };
  Kind kind = Kind::kCrossEntropy;
  double q = 0.7;
  // kGeneralized: the cross-entropy at the pixels within this many pixels
  // (a square window) of the outline of the model's mask; 0: nowhere.
  int outline_band = 0;
  // q of the generalized loss within the band; 0: the cross-entropy there.
  // Why a q between: the cross-entropy regresses S_j on the mean of the
  // views' masks, which jittered outlines bring to about a half along the
  // true outline, so a share of its pixels falls below tau (false
  // negatives along every outline); a small q sharpens that mean less than
  // q does elsewhere, which leaves the Gaussians' tails less room to dilate.
  // Measured at 0.35 (docs/benchmarks.md, "A q between the cross-entropy and
  // the rest in the band" and the section after it): it closed two real
  // captures' gap to exact masks, and it lost more where an object's masks
  // were loose in every view than it gained where they were tight (the soft
  // edge undoes part of a dilation), so 0 stays the default.
  double outline_q = 0;
  float mask_threshold = 0.5f;  // tau, the rendered masks' threshold on S_j
};

// Per pixel of a binary image (1 inside): 1 if a pixel of the other value
// lies within `radius` pixels of it (in a (2 radius + 1)^2 square), that is
// within `radius` pixels of the outline.
std::vector<uint8_t> near_outline(std::span<const uint8_t> inside, int width, int height,
                                  int radius);

struct ObjectLossOptions {
  float weight = 0.f;        // lambda_o (the paper: 0.1); 0 turns the loss off
  int objects_per_step = 3;  // M
  // Folder of ID maps inside the scene; "auto": the one the scene's layout
  // prefers among those present (dataset_layout.h).
  std::string id_maps = "auto";
  // Corrections of the maps' track IDs found by op2gs-vote (its summary.json,
  // read_id_corrections): IDs counted as another (one object's lost and
  // re-found track), and per view the IDs not sampled there (a segment that
  // covered another object too).
  std::map<int32_t, int32_t> id_remap;
  std::map<std::string, std::vector<int32_t>> ignored_ids;  // by view name
  // Vote protection: a Gaussian whose label won at least this share of its
  // votes (op2gs-vote's label_agreement.npy) is taken to belong to its
  // object: its sigma* stays at least its sigma (keep_in_mask), and the
  // object loss does not move or reshape it, which the photos alone do.
  // Above sigma, the loss moves its sigma* both ways (a glass object's faint
  // Gaussians must rise to show in the mask). Why: the loss regresses
  // sigma* on every view's mask, so the views whose mask missed a part of
  // the object (SAM2 and DEVA do, often over runs of frames) pull the
  // interior's sigma* down and punch holes in the masks, which boundary IoU
  // punishes hard at full resolution, while the majority vote already
  // outvoted those views. Mislabelled Gaussians (floaters,
  // Gaussians straddling a border) split their votes and stay free to fall.
  // 0: off, every sigma* follows the loss (the paper).
  float protected_agreement = 0.f;
  std::filesystem::path label_agreement;  // the .npy; required when protecting
  // The paper's object loss reaches sigma* and the Gaussians' position and
  // shape. false: sigma* alone, the photos alone shape the Gaussians (the
  // ablation of that gradient path). It was tried against masks loose or
  // tight on an object in every view, which the geometry path follows; it
  // costs about 2 points with exact and SAM2-like masks on a real capture,
  // so it stays off (docs/benchmarks.md, "Real captures").
  bool reshapes_geometry = true;
  PixelLoss pixel_loss;  // the paper's cross-entropy by default
  void Check() const;    // throws std::invalid_argument
};

// Per Gaussian: 1 if its label agreement in `file` (float array of shape
// (N,)) is at least `threshold`. Throws InputError naming the file when it
// cannot be read or holds other than `gaussians` values.
std::vector<uint8_t> read_protected_gaussians(const std::filesystem::path& file, float threshold,
                                              size_t gaussians);

// The labels that render each object's protected and unprotected Gaussians
// to separate maps (RenderSettings::labels): an unprotected Gaussian's label
// l becomes l + offset (split_label_offset).
std::vector<int32_t> split_labels(const std::vector<int32_t>& labels,
                                  const std::vector<uint8_t>& keep, int32_t offset);

// Fills the corrections from op2gs-vote's summary.json ("joined_ids",
// "merged_segments"); a summary without them leaves the options as they are.
// Throws InputError naming the file when it is malformed.
void read_id_corrections(const std::filesystem::path& vote_summary, ObjectLossOptions& options);

// The map with the corrections applied to its pixels (id_remap).
void remap_ids(IdMap& ids, const std::map<int32_t, int32_t>& id_remap);

// The object IDs (not 0) that occur in a map, ascending.
std::vector<int32_t> objects_in_map(const IdMap& ids);

// Up to m distinct IDs of `present`, uniformly without replacement.
std::vector<int32_t> sample_objects(const std::vector<int32_t>& present, int m,
                                    std::mt19937_64& rng);

// The loss (before the weight) of the occupancy maps (one W * H plane per
// label, in the order of `labels`) against the masks ids == label. When grad
// is not null it receives weight * dLoss/dS, same layout. S is clamped to
// [1e-6, 1 - 1e-6] inside the logarithms, as a safeguard like torch's
// clamped BCE, and likewise inside the powers of the generalized loss.
double object_loss(std::span<const float> maps, const std::vector<int32_t>& labels,
                   const IdMap& ids, float weight, std::vector<float>* grad,
                   const PixelLoss& pixel_loss = {});

// An offset that takes every label, and every ID an ID map can hold (16
// bits; a map may show IDs no Gaussian carries), past all of them.
int32_t split_label_offset(const std::vector<int32_t>& labels);

// The object loss of maps split in two (split_labels): maps holds 2M
// planes, the M objects' occupancy from their protected Gaussians, then from
// the others. The loss is object_loss of their sums, S_j; grad gets its
// dLoss/dS_j for both halves (2M planes).
double split_object_loss(std::span<const float> maps, const std::vector<int32_t>& labels,
                         const IdMap& ids, float weight, std::vector<float>* grad,
                         const PixelLoss& pixel_loss = {});

// Raises a protected Gaussian's sigma* to its sigma where it fell below (the
// projection after each step): it is at least as present in its object's
// mask as in the picture. Above that, sigma* moves freely, both ways, so
// the noise of the masks does not ratchet it up.
void keep_in_mask(std::span<float> instance_opacity_logits, std::span<const float> opacity_logits,
                  const std::vector<uint8_t>& keep);

}  // namespace splat
