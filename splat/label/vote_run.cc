#include "splat/label/vote_run.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_pipeline.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>

#include "splat/atomic_file.h"
#include "splat/checkpoint.h"
#include "splat/dataset_layout.h"
#include "splat/error.h"
#include "splat/id_maps.h"
#include "splat/label/palette.h"
#include "splat/label/vote_summary.h"
#include "splat/npy.h"
#include "splat/ply.h"

namespace splat {
namespace fs = std::filesystem;
using json = nlohmann::json;

void VoteRunOptions::Check() const {
  scene.Check();
  vote.Check();
  track_ids.Check();
  if (model.empty()) throw std::invalid_argument("the stage-one model is not set");
  if (id_maps.empty()) throw std::invalid_argument("the ID map folder name is empty");
  if (preview_views < 0) throw std::invalid_argument("preview_views must be >= 0");
}

namespace {

// One training view, read and prepared for voting (in parallel with others).
struct PreparedView {
  size_t view = 0;
  Camera camera;  // at the ID map's resolution
  IdMap ids;
  DepthMap depth;
  std::vector<int32_t> ids_present;
  std::vector<int32_t> segments;  // IDs large enough to count as seen (track_ids.h)
  std::exception_ptr error;       // why the view could not be prepared
};

// Gaussian centres that vote in the view, as coloured dots over the dimmed photo.
ImageRGB label_preview(const GaussianModel& model, const Camera& camera, const ImageRGB& photo,
                       const DepthMap* depth, const VoteOptions& options) {
  ImageRGB image = photo;
  for (float& v : image.data) v *= 0.3f;
  const CentreVisibility visibility(camera, depth, options);
  struct Dot {
    float z;
    int x, y;
    int32_t label;
  };
  std::vector<Dot> dots;
  for (size_t j = 0; j < model.size(); ++j) {
    Dot d;
    if (visibility.test(&model.means[3 * j], d.x, d.y, d.z))
      dots.push_back({d.z, d.x, d.y, model.labels[j]});
  }
  std::sort(dots.begin(), dots.end(), [](const Dot& a, const Dot& b) { return a.z > b.z; });
  for (const Dot& d : dots) {
    const auto c = d.label ? label_color(d.label) : std::array<float, 3>{0.5f, 0.5f, 0.5f};
    std::copy(c.begin(), c.end(), image.pixel(d.x, d.y));
  }
  return image;
}

std::string stem_of(const std::string& name) { return fs::path(name).stem().string(); }

// Checks that every training view has an ID map; returns the views to use.
std::vector<size_t> views_with_maps(const Scene& scene, const std::vector<size_t>& train,
                                    const fs::path& folder, bool allow_missing,
                                    std::vector<std::string>& skipped) {
  if (!fs::is_directory(folder))
    throw InputError(folder, "no ID map folder (precomputed SAM2 masks, one PNG per image)");
  std::vector<size_t> used;
  for (size_t v : train) {
    const std::string& name = scene.views()[v].name;
    if (!find_id_map(folder, name).empty()) {
      used.push_back(v);
      continue;
    }
    if (!allow_missing) require_id_map(folder, name, "(--allow-missing skips such views)");
    spdlog::warn("no ID map for training view {}; skipped", name);
    skipped.push_back(name);
  }
  if (used.empty()) throw InputError(folder, "no training view has an ID map");
  return used;
}

// Per Gaussian, the share of its votes that went to its label (0: no votes).
std::vector<double> label_agreement(const LabelVotes& votes) {
  std::vector<double> a(votes.size(), 0.0);
  for (size_t j = 0; j < a.size(); ++j)
    if (const uint32_t n = votes.votes(j)) a[j] = double(votes.votes_for_label(j)) / n;
  return a;
}

// Render states for the depth maps, handed from view to view: a state holds
// buffers for every Gaussian, and allocating them afresh in every view costs
// as much as a good part of the render.
class RenderStatePool {
 public:
  std::unique_ptr<RenderState> take() {
    std::lock_guard lock(mutex_);
    if (free_.empty()) return nullptr;
    std::unique_ptr<RenderState> state = std::move(free_.back());
    free_.pop_back();
    return state;
  }
  void give(std::unique_ptr<RenderState> state) {
    std::lock_guard lock(mutex_);
    free_.push_back(std::move(state));
  }

 private:
  std::mutex mutex_;
  std::vector<std::unique_ptr<RenderState>> free_;
};

// What the steps of a voting run share: the model, the scene and its split,
// and the training views with an ID map (those without are skipped into
// `skipped` when the options allow it).
struct VotingRun {
  VotingRun(const fs::path& scene_dir, const VoteRunOptions& options,
            std::vector<std::string>& skipped)
      : o(options),
        stage_one(read_model_file(options.model)),
        scene(Scene::load(scene_dir, options.scene)),
        split(split_views(*scene, options.split)),
        folder(scene->root() / resolve_id_map_folder(scene->root(), options.id_maps)),
        used(views_with_maps(*scene, split.train, folder, options.allow_missing, skipped)) {}

  // The depth test, not the frustum only.
  bool cull() const { return o.vote.visibility == VoteVisibility::kDepth; }

  const VoteRunOptions& o;
  CheckpointModel stage_one;
  std::unique_ptr<Scene> scene;
  ViewSplit split;
  fs::path folder;           // of the ID maps
  std::vector<size_t> used;  // training views with an ID map
  CpuRenderer renderer;
};

// A training view's ID map, its camera at the map's size, and the depth
// that tells which Gaussians it sees.
void prepare_view(const VotingRun& run, size_t v, RenderStatePool& states, PreparedView& p) {
  const View& view = run.scene->views()[v];
  const fs::path file = find_id_map(run.folder, view.name);
  p.ids = read_id_map(file);
  check_id_map_aspect(file, p.ids, view.camera.width, view.camera.height);
  p.camera = view.camera.resized(p.ids.width, p.ids.height);
  if (run.cull()) {
    std::unique_ptr<RenderState> state = states.take();
    p.depth = render_depth_map(run.renderer, run.stage_one.model, p.camera, run.o.vote, &state);
    states.give(std::move(state));
  }
  p.ids_present = ids_in_map(p.ids);
  p.segments = segments_in_map(p.ids, run.o.track_ids.min_segment_share);
}

// Reading a map and rendering its depth run for several views at once;
// votes are added one view at a time, in order. No exception crosses the
// pipeline (TBB would leak the views in flight): a view that fails carries
// its error to the last step, which stops there; the first failing view's
// error, in view order, is rethrown.
void collect_votes(VotingRun& run, LabelVotes& votes, std::map<int, size_t>& views_per_id,
                   IdCooccurrence& cooccurrence) {
  const GaussianModel& model = run.stage_one.model;
  const VoteOptions& vote = run.o.vote;
  RenderStatePool states;
  size_t next = 0;
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  tbb::parallel_pipeline(
      4, tbb::make_filter<void, size_t>(tbb::filter_mode::serial_in_order,
                                        [&](tbb::flow_control& fc) -> size_t {
                                          if (next == run.used.size() || failed) fc.stop();
                                          return next < run.used.size() ? run.used[next++] : 0;
                                        }) &
             tbb::make_filter<size_t, std::shared_ptr<PreparedView>>(
                 tbb::filter_mode::parallel,
                 [&](size_t v) {
                   auto p = std::make_shared<PreparedView>();
                   p->view = v;
                   try {
                     prepare_view(run, v, states, *p);
                   } catch (...) {
                     p->error = std::current_exception();
                     failed = true;
                   }
                   return p;
                 }) &
             tbb::make_filter<std::shared_ptr<PreparedView>, void>(
                 tbb::filter_mode::serial_in_order, [&](const std::shared_ptr<PreparedView>& p) {
                   if (error) return;
                   if (p->error) {
                     error = p->error;
                     return;
                   }
                   votes.add_view(model, p->camera, p->ids, run.cull() ? &p->depth : nullptr, vote);
                   for (int32_t id : p->ids_present) ++views_per_id[id];
                   cooccurrence.add_view(p->segments);
                 }));
  if (error) std::rethrow_exception(error);
}

// Previews over a few training views, evenly spaced.
void write_previews(const VotingRun& run, const fs::path& out) {
  const size_t previews = std::min<size_t>(run.o.preview_views, run.used.size());
  for (size_t k = 0; k < previews; ++k) {
    const size_t v = run.used[k * run.used.size() / previews];
    const Camera& cam = run.scene->views()[v].camera;
    const GaussianModel& model = run.stage_one.model;
    const DepthMap depth =
        run.cull() ? render_depth_map(run.renderer, model, cam, run.o.vote) : DepthMap{};
    write_image_rgb(
        out / "preview" / (stem_of(run.scene->views()[v].name) + ".png"),
        label_preview(model, cam, *run.scene->image(v), run.cull() ? &depth : nullptr, run.o.vote));
  }
}

// The ablation's baseline label maps of the test views; returns their number.
size_t write_baseline_maps(const VotingRun& run, const fs::path& out) {
  RenderSettings settings;
  settings.color = settings.depth = false;
  settings.sh_degree = std::min(run.stage_one.sh_degree, kMaxShDegree);
  settings.baseline_label_map = true;
  for (size_t v : run.split.test) {
    const View& view = run.scene->views()[v];
    const RenderOutput r = run.renderer.render(run.stage_one.model, view.camera, settings);
    write_label_map(out / "baseline", stem_of(view.name), r.baseline_label, r.width, r.height);
  }
  return run.split.test.size();
}

// One object seen under several IDs gets one label (track_ids.h); returns
// the ID each joined ID now counts as.
std::map<int32_t, int32_t> join_switched_ids(LabelVotes& votes, const IdCooccurrence& cooccurrence,
                                             const TrackIdOptions& options, VoteRunResult& result) {
  const TrackIdResult joined = find_switched_ids(votes.id_association(), cooccurrence, options);
  for (const JoinedIds& g : joined.groups)
    spdlog::info("ID {} and {} name one object (a lost and re-found track): joined as {}", g.kept,
                 fmt::join(g.joined, ", "), g.kept);
  if (joined.groups.empty()) spdlog::info("no ID names an object another ID names");
  votes.remap_ids(joined.canonical);
  result.joined_ids = joined.groups;
  result.id_pairs = joined.pairs;
  return joined.canonical;
}

// The segments that cover a second object, per training view (track_ids.h).
json merged_segments_json(VotingRun& run, const std::vector<int32_t>& labels,
                          const std::map<int32_t, int32_t>& canonical, VoteRunResult& result) {
  json out = json::array();
  RenderStatePool states;
  for (size_t v : run.used) {
    PreparedView p;
    prepare_view(run, v, states, p);
    for (const MergedSegment& m : find_merged_segments(run.stage_one.model, labels, p.camera, p.ids,
                                                       run.cull() ? &p.depth : nullptr, run.o.vote,
                                                       canonical, run.o.track_ids))
      out.push_back({{"view", run.scene->views()[v].name}, {"id", m.id}, {"covers", m.covers}});
  }
  result.merged_segments = out.size();
  spdlog::info("{} segments cover a second object (merges); stage two leaves them out", out.size());
  return out;
}

json joined_ids_json(const std::vector<JoinedIds>& groups) {
  json j = json::array();
  for (const JoinedIds& g : groups) j.push_back({{"kept", g.kept}, {"joined", g.joined}});
  return j;
}

}  // namespace

VoteRunResult run_voting(const fs::path& scene_dir, const fs::path& out, const VoteRunOptions& o) {
  o.Check();
  const auto t0 = std::chrono::steady_clock::now();
  VoteRunResult result;
  VotingRun run(scene_dir, o, result.views_skipped);
  GaussianModel& model = run.stage_one.model;
  spdlog::info("{} Gaussians (iteration {}); voting over {} training views with {}/", model.size(),
               run.stage_one.iteration, run.used.size(), run.folder.filename().string());

  // Voting passes over every Gaussian in every view: in spatial order, its
  // reads of the depth and ID maps and the depth render's tile lists hit the
  // cache far more often. The model's own order is restored before writing.
  const std::vector<uint32_t> order = spatial_order(model);
  reorder_gaussians(model, order);
  LabelVotes votes(model.size());
  std::map<int, size_t> views_per_id;
  IdCooccurrence cooccurrence;
  collect_votes(run, votes, views_per_id, cooccurrence);
  if (views_per_id.empty() || views_per_id.rbegin()->first <= 0)
    throw InputError(run.folder,
                     "no training view's ID map holds an object ID (every pixel is "
                     "0, background): nothing to vote for");
  result.views_used = run.used.size();
  std::map<int32_t, int32_t> canonical;
  if (o.join_switched_ids) canonical = join_switched_ids(votes, cooccurrence, o.track_ids, result);
  model.labels = votes.labels();
  model.has_labels = true;
  // Still in the voting pass's order, which the second pass wants too.
  const json merged =
      o.find_merges ? merged_segments_json(run, model.labels, canonical, result) : json();

  json summary = vote_summary_json(model, votes, views_per_id,
                                   read_object_names(run.folder / "objects.json"), result);
  std::vector<double> agreement = label_agreement(votes);
  const std::vector<uint32_t> back = inverse_order(order);
  reorder_gaussians(model, back);
  write_gaussian_ply(out / "point_cloud.ply", model);
  reorder_array(agreement, 1, back);
  write_npy_f64(out / "label_agreement.npy", agreement, {agreement.size()});
  summary["model"] = o.model.string();
  summary["iteration"] = run.stage_one.iteration;
  summary["id_maps"] = run.folder.string();
  summary["views_used"] = result.views_used;
  summary["views_skipped"] = result.views_skipped;
  summary["visibility"] = run.cull() ? "depth" : "frustum";
  summary["depth_tolerance"] = o.vote.depth_tolerance;
  if (o.join_switched_ids) {
    summary["joined_ids"] = joined_ids_json(result.joined_ids);
    json pairs = json::array();
    for (const IdPair& p : result.id_pairs)
      pairs.push_back({{"ids", {p.a, p.b}},
                       {"association", {p.a_to_b, p.b_to_a}},
                       {"views", {p.views_a, p.views_b}},
                       {"views_together", p.together}});
    summary["id_pairs"] = pairs;  // why IDs were or were not joined
  }
  if (o.find_merges) summary["merged_segments"] = merged;

  write_previews(run, out);
  if (o.baseline_maps) summary["baseline_views"] = write_baseline_maps(run, out);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  summary["seconds"] = result.seconds;
  write_text_atomically(out / "summary.json", summary.dump(2) + "\n");
  return result;
}

}  // namespace splat
