#include "splat/train/object_loss.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/id_maps.h"
#include "splat/json_integer.h"
#include "splat/npy.h"

namespace splat {

void read_id_corrections(const std::filesystem::path& file, ObjectLossOptions& o) {
  if (!std::filesystem::exists(file)) return;
  try {
    const nlohmann::json j = nlohmann::json::parse(read_text_file(file));
    if (j.contains("joined_ids"))
      for (const auto& g : j.at("joined_ids"))
        for (const auto& id : g.at("joined"))
          o.id_remap[json_integer<int32_t>(id, file, "joined")] =
              json_integer<int32_t>(g.at("kept"), file, "kept");
    if (j.contains("merged_segments"))
      for (const auto& m : j.at("merged_segments"))
        o.ignored_ids[m.at("view").get<std::string>()].push_back(
            json_integer<int32_t>(m.at("id"), file, "id"));
  } catch (const std::exception& e) {
    throw InputError(file, std::string("not op2gs-vote's summary: ") + e.what());
  }
}

void remap_ids(IdMap& ids, const std::map<int32_t, int32_t>& id_remap) {
  if (id_remap.empty()) return;
  for (uint16_t& id : ids.ids)
    if (const auto it = id_remap.find(id); it != id_remap.end()) id = uint16_t(it->second);
}

void ObjectLossOptions::Check() const {
  if (!(weight >= 0)) throw std::invalid_argument("the object loss weight must be >= 0");
  if (objects_per_step < 1) throw std::invalid_argument("objects per step must be >= 1");
  if (weight > 0 && id_maps.empty()) throw std::invalid_argument("no ID map folder given");
  if (!(protected_agreement >= 0 && protected_agreement <= 1))
    throw std::invalid_argument("the protected label agreement must be in [0, 1]");
  if (pixel_loss.kind == PixelLoss::Kind::kGeneralized && !(pixel_loss.q > 0 && pixel_loss.q <= 1))
    throw std::invalid_argument("the generalized cross-entropy's q must be in (0, 1]");
  if (pixel_loss.outline_band < 0) throw std::invalid_argument("the outline band must be >= 0");
  if (!(pixel_loss.outline_q >= 0 && pixel_loss.outline_q <= 1))
    throw std::invalid_argument(
        "the generalized cross-entropy's q near the outline must be in [0, 1]");
  if (pixel_loss.outline_q > 0 &&
      !(pixel_loss.kind == PixelLoss::Kind::kGeneralized && pixel_loss.outline_band > 0))
    throw std::invalid_argument(
        "a q near the outline needs the generalized loss with an outline band (robust-outline)");
  if (protected_agreement > 0 && label_agreement.empty())
    throw std::invalid_argument("protecting sigma* needs op2gs-vote's label agreement file");
}

std::vector<uint8_t> read_protected_gaussians(const std::filesystem::path& file, float threshold,
                                              size_t gaussians) {
  if (!std::filesystem::exists(file))
    throw InputError(file, "no label agreement; run op2gs-vote (which writes it) on this model");
  std::vector<size_t> shape;
  const std::vector<double> agreement = read_npy(file, &shape);
  if (shape.size() != 1 || agreement.size() != gaussians)
    throw InputError(file, fmt::format("{} label agreements for {} Gaussians; run op2gs-vote "
                                       "again on this model",
                                       agreement.size(), gaussians));
  std::vector<uint8_t> keep(gaussians);
  for (size_t i = 0; i < gaussians; ++i) keep[i] = agreement[i] >= threshold;
  return keep;
}

std::vector<int32_t> objects_in_map(const IdMap& ids) {
  std::vector<int32_t> objects = ids_in_map(ids);
  if (!objects.empty() && objects.front() == 0) objects.erase(objects.begin());
  return objects;
}

std::vector<int32_t> sample_objects(const std::vector<int32_t>& present, int m,
                                    std::mt19937_64& rng) {
  std::vector<int32_t> pool = present, out;
  while (int(out.size()) < m && !pool.empty()) {
    const size_t k = std::uniform_int_distribution<size_t>(0, pool.size() - 1)(rng);
    out.push_back(pool[k]);
    pool.erase(pool.begin() + long(k));
  }
  return out;
}

namespace {

// The clamp of S inside the logarithms.
constexpr double kLow = 1e-6, kHigh = 1 - kLow;

// weight * scale * dLoss/dS of one plane: zero where the clamp is active.
// Its own loop, without the logarithm, so that it vectorises.
void object_loss_gradient(const float* S, const uint16_t* ids, int32_t label, size_t pixels,
                          double weight_scale, float* g) {
  for (size_t p = 0; p < pixels; ++p) {
    const double b = ids[p] == label ? 1.0 : 0.0;
    const double s = std::min(std::max(double(S[p]), kLow), kHigh);  // std::clamp, branch-free
    // Computed everywhere, then masked to +0 by its bits: with a select GCC
    // moves the division under the condition and, as it may trap, does not
    // vectorise the loop (s is clamped, so the division is always finite).
    const float value = float(weight_scale * (s - b) / (s * (1 - s)));
    const uint32_t keep = (S[p] > kLow) & (S[p] < kHigh) ? ~0u : 0u;
    g[p] = std::bit_cast<float>(std::bit_cast<uint32_t>(value) & keep);
  }
}

// The sum over one plane of -[b log s + (1 - b) log(1 - s)]. With b 0 or 1
// that is -log(b ? s : 1 - s), the same double; and where the clamp is
// active (most pixels: no Gaussian of the object reaches them, S = 0) s is
// a clamp bound, whose logarithms are computed once.
double object_loss_sum(const float* S, const uint16_t* ids, int32_t label, size_t pixels) {
  const double log_low = std::log(kLow), log_one_minus_low = std::log(1 - kLow);
  const double log_high = std::log(kHigh), log_one_minus_high = std::log(1 - kHigh);
  double sum = 0;
  for (size_t p = 0; p < pixels; ++p) {
    const bool b = ids[p] == label;
    if (S[p] <= kLow)
      sum -= b ? log_low : log_one_minus_low;
    else if (S[p] >= kHigh)
      sum -= b ? log_high : log_one_minus_high;
    else
      sum -= std::log(b ? double(S[p]) : 1 - double(S[p]));
  }
  return sum;
}

// The generalized cross-entropy (PixelLoss): weight * scale * dLoss/dS of
// one plane, d/dS (1 - p^q) / q = -p^(q-1) dp/dS, zero where the clamp is
// active. Where band (if not null) is 1, q is band_q, and band_q = 0 is the
// cross-entropy's (s - b) / (s (1 - s)). The powers only where S is not
// clamped: most pixels are.
void generalized_loss_gradient(const float* S, const uint16_t* ids, int32_t label, size_t pixels,
                               double weight_scale, double q, const uint8_t* band, double band_q,
                               float* g) {
  for (size_t p = 0; p < pixels; ++p) {
    if (!(S[p] > kLow && S[p] < kHigh)) {
      g[p] = 0.f;
      continue;
    }
    const double s = S[p];
    const bool b = ids[p] == label;
    const bool in_band = band && band[p];
    const double q_here = in_band ? band_q : q;
    if (in_band && band_q == 0)
      g[p] = float(weight_scale * (s - double(b)) / (s * (1 - s)));  // as the paper's
    else
      g[p] = float(b ? -weight_scale * std::pow(s, q_here - 1)
                     : weight_scale * std::pow(1 - s, q_here - 1));
  }
}

// The sum over one plane of (1 - p^q) / q, p = s where b, else 1 - s, s
// clamped; with band_q for q where band (if not null) is 1, and -log p
// there if band_q = 0. Where the clamp is active (most pixels) the terms of
// the clamp's bounds, computed once.
double generalized_loss_sum(const float* S, const uint16_t* ids, int32_t label, size_t pixels,
                            double q, const uint8_t* band, double band_q) {
  const auto loss_at = [](double p, double q_here) {
    return q_here == 0 ? -std::log(p) : (1 - std::pow(p, q_here)) / q_here;
  };
  // The terms where S is clamped: [in the band][S at the high bound][b].
  double at_bound[2][2][2];
  for (int in_band = 0; in_band < 2; ++in_band)
    for (int high = 0; high < 2; ++high)
      for (int b = 0; b < 2; ++b) {
        const double s = high ? kHigh : kLow, prob = b ? s : 1 - s;
        at_bound[in_band][high][b] = loss_at(prob, in_band ? band_q : q);
      }
  double sum = 0;
  for (size_t p = 0; p < pixels; ++p) {
    const bool b = ids[p] == label;
    const bool in_band = band && band[p];
    if (S[p] <= kLow)
      sum += at_bound[in_band][0][b];
    else if (S[p] >= kHigh)
      sum += at_bound[in_band][1][b];
    else
      sum += loss_at(b ? double(S[p]) : 1 - double(S[p]), in_band ? band_q : q);
  }
  return sum;
}

// The pixels of one task of the object loss: the gradient and the sum are
// computed in chunks of this many pixels of a plane, and the chunks' sums
// added in order, so the loss is the same double whatever the threads.
constexpr size_t kLossChunk = size_t(1) << 16;

// Per plane, 1 within pixel_loss.outline_band pixels of the outline of the
// model's mask of the object (S >= tau); empty where the loss has no band.
std::vector<std::vector<uint8_t>> outline_bands(std::span<const float> maps, size_t m,
                                                const IdMap& ids, const PixelLoss& pixel_loss) {
  std::vector<std::vector<uint8_t>> bands(m);
  if (pixel_loss.kind != PixelLoss::Kind::kGeneralized || pixel_loss.outline_band <= 0)
    return bands;
  const size_t pixels = ids.ids.size();
  tbb::parallel_for(size_t(0), m, [&](size_t j) {
    const float* S = &maps[j * pixels];
    std::vector<uint8_t> inside(pixels);
    // Locals, not references: a byte store may alias what a reference reaches.
    uint8_t* in = inside.data();
    const float tau = pixel_loss.mask_threshold;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, kLossChunk),
                      [S, in, tau](const auto& r) {
                        for (size_t p = r.begin(); p < r.end(); ++p) in[p] = S[p] >= tau;
                      });
    bands[j] = near_outline(inside, ids.width, ids.height, pixel_loss.outline_band);
  });
  return bands;
}

}  // namespace

std::vector<uint8_t> near_outline(std::span<const uint8_t> inside, int width, int height,
                                  int radius) {
  const size_t pixels = inside.size();
  if (pixels != size_t(width) * size_t(height))
    throw std::invalid_argument("near_outline: sizes differ");
  if (pixels == 0) return {};
  // The square window holds a pixel inside where the dilation is 1, and one
  // outside where the erosion is 0; OpenCV's default border leaves pixels
  // off the image out of both. In stripes of rows, in parallel (OpenCV
  // runs a morphology on one thread): a stripe is a view into the whole
  // image, whose rows beyond the stripe OpenCV reads as its border, so each
  // stripe is exactly its rows of the whole image's result.
  const cv::Mat in(height, width, CV_8U, const_cast<uint8_t*>(inside.data()));
  const cv::Mat window =
      cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * radius + 1, 2 * radius + 1));
  // One stripe per thread (each call of a morphology sets up its filter,
  // and a stripe reads its neighbours' rows within the radius again), of
  // at least kMinRows rows.
  constexpr int kMinRows = 128;
  const int stripes = std::clamp(height / kMinRows, 1, tbb::this_task_arena::max_concurrency());
  std::vector<uint8_t> near(pixels);
  tbb::parallel_for(0, stripes, [&](int k) {
    const int first = int(int64_t(height) * k / stripes),
              last = int(int64_t(height) * (k + 1) / stripes);
    cv::Mat any_in, all_in;
    cv::dilate(in.rowRange(first, last), any_in, window);
    cv::erode(in.rowRange(first, last), all_in, window);
    const uint8_t *any = any_in.data, *all = all_in.data;  // not reloaded after each store
    uint8_t* out = &near[size_t(first) * size_t(width)];
    const size_t n = size_t(last - first) * size_t(width);
    for (size_t p = 0; p < n; ++p) out[p] = any[p] & (all[p] ^ 1);
  });
  return near;
}

double object_loss(std::span<const float> maps, const std::vector<int32_t>& labels,
                   const IdMap& ids, float weight, std::vector<float>* grad,
                   const PixelLoss& pixel_loss) {
  const size_t pixels = ids.ids.size(), m = labels.size();
  if (maps.size() != m * pixels) throw std::invalid_argument("object_loss: map sizes differ");
  if (grad) grad->resize(maps.size());  // every value is written
  if (m == 0 || pixels == 0) return 0;
  const double scale = 1.0 / (double(m) * double(pixels));
  const bool generalized = pixel_loss.kind == PixelLoss::Kind::kGeneralized;
  const double q = pixel_loss.q;
  const std::vector<std::vector<uint8_t>> bands = outline_bands(maps, m, ids, pixel_loss);
  // Every chunk of every plane in parallel: with one sampled object (a
  // scene of one object, or M = 1) the planes alone would leave all threads
  // but one idle.
  const size_t chunks = (pixels + kLossChunk - 1) / kLossChunk;
  std::vector<double> sums(m * chunks);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, m * chunks, 1), [&](const auto& range) {
    for (size_t task = range.begin(); task < range.end(); ++task) {
      const size_t j = task / chunks, at = (task % chunks) * kLossChunk;
      const size_t n = std::min(kLossChunk, pixels - at);
      const float* S = &maps[j * pixels + at];
      const uint16_t* chunk_ids = &ids.ids[at];
      const uint8_t* band = bands[j].empty() ? nullptr : bands[j].data() + at;
      if (grad) {
        float* g = &(*grad)[j * pixels + at];
        if (generalized)
          generalized_loss_gradient(S, chunk_ids, labels[j], n, weight * scale, q, band,
                                    pixel_loss.outline_q, g);
        else
          object_loss_gradient(S, chunk_ids, labels[j], n, weight * scale, g);
      }
      sums[task] = generalized ? generalized_loss_sum(S, chunk_ids, labels[j], n, q, band,
                                                      pixel_loss.outline_q)
                               : object_loss_sum(S, chunk_ids, labels[j], n);
    }
  });
  double loss = 0;
  for (double sum : sums) loss += sum;
  return loss * scale;
}

std::vector<int32_t> split_labels(const std::vector<int32_t>& labels,
                                  const std::vector<uint8_t>& keep, int32_t offset) {
  if (labels.size() != keep.size())
    throw std::invalid_argument("split_labels: one flag per Gaussian expected");
  std::vector<int32_t> out(labels.size());
  for (size_t i = 0; i < labels.size(); ++i) out[i] = keep[i] ? labels[i] : labels[i] + offset;
  return out;
}

void keep_in_mask(std::span<float> instance_opacity_logits, std::span<const float> opacity_logits,
                  const std::vector<uint8_t>& keep) {
  if (instance_opacity_logits.size() != keep.size() || opacity_logits.size() != keep.size())
    throw std::invalid_argument("keep_in_mask: one flag per Gaussian expected");
  for (size_t i = 0; i < keep.size(); ++i)
    if (keep[i])
      instance_opacity_logits[i] = std::max(instance_opacity_logits[i], opacity_logits[i]);
}

int32_t split_label_offset(const std::vector<int32_t>& labels) {
  int32_t offset = 1 << 16;
  for (int32_t l : labels) offset = std::max(offset, l + 1);
  return offset;
}

double split_object_loss(std::span<const float> maps, const std::vector<int32_t>& labels,
                         const IdMap& ids, float weight, std::vector<float>* grad,
                         const PixelLoss& pixel_loss) {
  const size_t half = labels.size() * ids.ids.size();
  if (maps.size() != 2 * half) throw std::invalid_argument("split_object_loss: map sizes differ");
  std::vector<float> whole(half);
  for (size_t k = 0; k < half; ++k) whole[k] = maps[k] + maps[half + k];
  const double loss = object_loss(whole, labels, ids, weight, grad, pixel_loss);
  if (grad) {  // the same gradient for both halves (inserting a vector into itself is undefined)
    grad->resize(2 * half);
    std::copy_n(grad->begin(), half, grad->begin() + long(half));
  }
  return loss;
}

}  // namespace splat
