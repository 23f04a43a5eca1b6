#!/usr/bin/env bash
# Sets up (Debian packages + Release build) and runs the OP2GS pipeline on the
# built-in synthetic demo scene, stage by stage:
#
#   op2gs-synth   the scene (photos, SAM2-like masks, ground truth), no model
#   op2gs-sfm     COLMAP from the photos alone
#   op2gs-train   stage one (3,000 iterations of a 4,500-iteration schedule)
#   op2gs-vote    labels by majority vote of the sam2/ masks
#   op2gs-learn   stage two: sigma* with the random object loss, to 4,500
#   op2gs-render  test-view RGB, object masks and label maps
#   op2gs-eval    LERF-Mask mIoU / mBIoU of the dual-opacity masks and the baseline
#
# The schedule is the reference's shortened to fit a laptop (about 10 minutes
# on 2 cores); the make-style pipeline (pipeline/) will run the full one.
#
# Usage: scripts/demo.sh [demo folder]   (default: demo/)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
demo="${1:-$root/demo}"
bin="$root/build/stages"
"$root/scripts/setup.sh"
mkdir -p "$demo"
step() { echo; echo "== $*"; }
step "1/7 synthetic scene -> $demo/photos"
"$bin/op2gs-synth" "$demo/photos" --no-sparse --force
step "2/7 SfM with COLMAP -> $demo/sfm"
"$bin/op2gs-sfm" "$demo/photos" "$demo/sfm" --gpu off
scene="$demo/sfm/scene"
work="$demo/work"
rm -rf "$work"
step "3/7 stage one -> $work"
"$bin/op2gs-train" "$scene" "$work" --iterations 3000 --schedule 4500 --densify-until 2250
step "4/7 label voting -> $work/vote"
"$bin/op2gs-vote" "$scene" "$work"
step "5/7 stage two -> $work/learn"
"$bin/op2gs-learn" "$scene" "$work" --iterations 4500 --schedule 4500
step "6/7 masks -> $work/render"
"$bin/op2gs-render" "$scene" "$work"
step "7/7 evaluation -> $work/metrics_masks.json"
"$bin/op2gs-eval" "$scene" --pred dual-opacity="$work/render/masks" \
  --pred baseline="$work/render/baseline_labels" --out "$work/metrics_masks.json"
echo
echo "demo done: masks in $work/render/masks_color/, label maps in $work/render/instance_labels_color/,"
echo "per-view scores in $work/metrics_masks.json, training curves in $work/training_curve.png"
