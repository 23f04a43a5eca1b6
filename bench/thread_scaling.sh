#!/usr/bin/env bash
# Thread scaling of training, 1 against 2 threads, paired, in each phase of
# the schedule (docs/benchmarks.md, "Thread scaling").
#
#   bench/thread_scaling.sh <op2gs build dir> <scene folder> <out dir>
#
# Phases, each run ROUNDS times with --threads 1, 2, 2, 1 in turn so that the
# machine's drift hits both counts alike:
#   early      stage one from the scene's SfM points (a few thousand large
#              Gaussians), STEPS iterations, before densification starts;
#   late       stage one resumed from MODEL's checkpoint (LATE_AT), STEPS
#              more, densification over;
#   stage-two  op2gs-learn from the same checkpoint with the labels of
#              LABELS (an op2gs-vote point cloud), STEPS iterations; run
#              only when LABELS is set.
# Each run's time per iteration is the median step of its train_log.jsonl
# after the first (bench/timing.sh); the views are decoded before the first
# iteration, so no step waits on a photo.
#
# Environment: DOWNSCALE (1), TRAIN_OPTS (scene options, e.g. "--split
# lerf"), LEARN_OPTS (op2gs-learn's, e.g. "--id-maps object_mask"), STEPS
# (100), ROUNDS (2), SCHEDULE (7500), LATE_AT (5000), MODEL (an op2gs
# stage-one work folder with checkpoints/latest.ckpt at LATE_AT; without it
# only the early phase runs), LABELS, PHASES (which of the phases to run;
# default all that MODEL and LABELS allow).
# Any failing step stops the script with its log's tail.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
# shellcheck source=bench/timing.sh
source "$here/timing.sh"
build="$(cd "$1" && pwd)"
scene="$(cd "$2" && pwd)"
out="$3"
downscale="${DOWNSCALE:-1}"
read -r -a train_opts <<< "${TRAIN_OPTS:-}"
read -r -a learn_opts <<< "${LEARN_OPTS:-}"
steps="${STEPS:-100}"
rounds="${ROUNDS:-2}"
schedule="${SCHEDULE:-7500}"
late_at="${LATE_AT:-5000}"
model="${MODEL:-}"
labels="${LABELS:-}"
bin="$build/stages"
mkdir -p "$out/logs"
out="$(cd "$out" && pwd)"
logs="$out/logs"

[ -x "$bin/op2gs-train" ] || fail "$bin/op2gs-train: missing (build op2gs first)"
for f in images sparse/0; do
  [ -e "$scene/$f" ] || fail "$scene/$f: missing (an op2gs scene folder: images/, sparse/0/)"
done
[ -z "$model" ] || [ -f "$model/checkpoints/latest.ckpt" ] ||
  fail "$model/checkpoints/latest.ckpt: missing (MODEL must be a stage-one work folder)"
[ -z "$labels" ] || [ -n "$model" ] || fail "LABELS needs MODEL (stage two starts from its checkpoint)"
[ -z "$labels" ] || [ -f "$labels" ] || fail "$labels: missing (LABELS: an op2gs-vote point cloud)"

never=100000000
common=("$scene" --resolution "$downscale" "${train_opts[@]}" --schedule "$schedule"
  --no-final-test --checkpoint-every "$never")
end=$((late_at + steps))

# Runs PHASE with THREADS threads in a fresh folder; prints its median step.
run_phase() {  # PHASE THREADS LABEL
  local phase="$1" threads="$2" label="$3" work="$out/run"
  rm -rf "$work"
  case "$phase" in
    early)
      step "$label" "$bin/op2gs-train" "${common[@]}" "$work" --threads "$threads" \
        --iterations "$steps" --densify-until 1
      op2gs_seconds "$work/train_log.jsonl" 1 "$steps"
      ;;
    late)
      resume_in_fresh_folder "$label" "$model/checkpoints/latest.ckpt" "$work" \
        "$bin/op2gs-train" "${common[@]}" --threads "$threads" --iterations "$end" \
        --densify-until "$late_at"
      op2gs_seconds "$work/train_log.jsonl" $((late_at + 1)) "$end"
      ;;
    stage-two)
      step "$label" "$bin/op2gs-learn" "${common[@]}" "$work" "${learn_opts[@]}" \
        --threads "$threads" --checkpoint "$model/checkpoints/latest.ckpt" --labels "$labels" \
        --iterations "$end"
      op2gs_seconds "$work/learn/train_log.jsonl" $((late_at + 1)) "$end"
      ;;
  esac
}

phases=(early)
[ -n "$model" ] && phases+=(late)
[ -n "$labels" ] && phases+=(stage-two)
if [ -n "${PHASES:-}" ]; then
  read -r -a wanted <<< "$PHASES"
  for phase in "${wanted[@]}"; do
    [[ " ${phases[*]} " == *" $phase "* ]] || fail "PHASES: $phase is not one of: ${phases[*]} (late needs MODEL, stage-two LABELS)"
  done
  phases=("${wanted[@]}")
fi
results="$out/results.jsonl"
: > "$results"
for round in $(seq "$rounds"); do
  for phase in "${phases[@]}"; do
    run=0
    for threads in 1 2 2 1; do
      run=$((run + 1))
      label="${phase}_round${round}_run${run}_${threads}t"
      seconds="$(run_phase "$phase" "$threads" "$label")"
      echo "round $round, $phase, $threads thread(s): $seconds s/it"
      printf '{"phase":"%s","threads":%d,"round":%d,"s_per_iteration":%s}\n' \
        "$phase" "$threads" "$round" "$seconds" >> "$results"
    done
  done
done
rm -rf "$out/run"

echo
echo "phase      1 thread s/it  2 threads s/it  speed-up (median of each)"
for phase in "${phases[@]}"; do
  pick() {
    sed -nE "/\"phase\":\"$phase\",\"threads\":$1,/ s/.*\"s_per_iteration\":([0-9.e+-]+).*/\1/p" \
      "$results"
  }
  one=$(pick 1 | median) two=$(pick 2 | median)
  awk -v p="$phase" -v a="$one" -v b="$two" 'BEGIN { printf "%-10s %14s %15s  %.2fx\n", p, a, b, a / b }'
done
