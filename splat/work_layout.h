#pragma once
// The work folder of one scene: where each stage writes its artifacts and
// where the stages after it find them. This is the one description of that
// layout: every stage's default paths and pipeline/Makefile's table of stage
// outputs follow it (docs/architecture.md draws the data flow).
//
//   <work>/sfm/                 op2gs-sfm; the scene the stages read is sfm/scene/
//   <work>/checkpoints/ ...     op2gs-train: a training folder (TrainingLayout);
//                               with --refine-poses also refined_poses.txt,
//                               which vote, render and embed then use
//   <work>/vote/                op2gs-vote: point_cloud.ply with labels,
//                               label_agreement.npy, summary.json,
//                               preview/, baseline/
//   <work>/learn/               op2gs-learn: a training folder (TrainingLayout)
//   <work>/render/              op2gs-render: rgb/, masks/, instance_labels/, ...
//   <work>/embed/               op2gs-embed: embeddings.json, crops
//   <work>/query/               op2gs-query: query.json, query.csv
//   <work>/eval/                op2gs-eval: metrics.json
//   <work>/report/              op2gs-report: report.html, report.md
//   <work>/viewer/              op2gs-viewer: the 3D viewer without a report

#include <filesystem>
#include <string>
#include <vector>

namespace splat {

// What a training run (stage one, or stage two in <work>/learn) writes.
struct TrainingLayout {
  std::filesystem::path root;

  std::filesystem::path checkpoints() const { return root / "checkpoints"; }
  // Resumable state, atomically replaced.
  std::filesystem::path latest_checkpoint() const { return checkpoints() / "latest.ckpt"; }
  // A checkpoint kept at that iteration (--keep-checkpoint-at), never replaced.
  std::filesystem::path checkpoint_at(int iteration) const {
    return checkpoints() / ("iteration_" + std::to_string(iteration) + ".ckpt");
  }
  std::filesystem::path point_clouds() const { return root / "point_cloud"; }
  // A standard 3DGS PLY of the model at that iteration.
  std::filesystem::path point_cloud(int iteration) const {
    return point_clouds() / ("iteration_" + std::to_string(iteration)) / "point_cloud.ply";
  }
  std::filesystem::path test() const { return root / "test"; }
  std::filesystem::path test_renders() const { return test() / "renders"; }
  std::filesystem::path metrics() const { return root / "metrics.json"; }
  std::filesystem::path log() const { return root / "train_log.jsonl"; }
  // The training views' refined poses (pose_file.h), with --refine-poses.
  std::filesystem::path refined_poses() const { return root / "refined_poses.txt"; }
  std::filesystem::path curve() const { return root / "training_curve.png"; }
};

struct WorkLayout {
  std::filesystem::path root;

  std::filesystem::path sfm() const { return root / "sfm"; }
  std::filesystem::path sfm_scene() const { return sfm() / "scene"; }
  TrainingLayout stage_one() const { return {root}; }
  // The refined poses that go with each stage's model, in order of
  // preference (splat::choose_pose_file): stage two's model was trained on
  // stage two's poses if it refined them, else on stage one's.
  std::vector<std::filesystem::path> refined_poses_of_stage_one_model() const {
    return {stage_one().refined_poses()};
  }
  std::vector<std::filesystem::path> refined_poses_of_stage_two_model() const {
    return {stage_two().refined_poses(), stage_one().refined_poses()};
  }
  std::filesystem::path vote() const { return root / "vote"; }
  // The stage-one model with one label per Gaussian.
  std::filesystem::path labelled_model() const { return vote() / "point_cloud.ply"; }
  // Per Gaussian of the labelled model, in its order: the share of its votes
  // that went to its label (0 without votes); float64, shape (N,).
  std::filesystem::path label_agreement() const { return vote() / "label_agreement.npy"; }
  // What the vote found: per object its Gaussians, views and name.
  std::filesystem::path vote_summary() const { return vote() / "summary.json"; }
  TrainingLayout stage_two() const { return {root / "learn"}; }
  std::filesystem::path render() const { return root / "render"; }
  std::filesystem::path embed() const { return root / "embed"; }
  std::filesystem::path embeddings() const { return embed() / "embeddings.json"; }
  std::filesystem::path query() const { return root / "query"; }
  std::filesystem::path query_results() const { return query() / "query.json"; }
  std::filesystem::path eval() const { return root / "eval"; }
  std::filesystem::path metrics() const { return eval() / "metrics.json"; }
  std::filesystem::path report() const { return root / "report"; }
  std::filesystem::path viewer() const { return root / "viewer"; }
};

}  // namespace splat
