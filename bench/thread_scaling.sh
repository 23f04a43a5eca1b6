#!/usr/bin/env bash
# Thread scaling of training, 1 against 2 threads, paired step by step, in
# each phase of the schedule (docs/benchmarks.md, "Thread scaling").
#
#   bench/thread_scaling.sh <op2gs build dir> <scene folder> <out dir>
#
# Each run trains with --alternate-threads 1 2 2 1: its iterations take 1,
# 2, 2, 1, 1, 2, ... threads in turn, so that a machine whose speed drifts
# within minutes (the VMs of docs/benchmarks.md, by a fifth or more) slows
# both counts alike, and training is the same model bit for bit as with
# either count. A step's time also depends on its view (by a third either
# way), and a run's views come in the same order every time, so even
# rounds swap the counts (2 1 1 2): over two rounds each iteration, its
# view and its model, is timed once with each count. Phases, each run
# ROUNDS times:
#   early      stage one from the scene's SfM points (a few thousand large
#              Gaussians), STEPS iterations, before densification starts;
#   late       stage one resumed from MODEL's checkpoint (LATE_AT), STEPS
#              more, densification over;
#   stage-two  op2gs-learn from the same checkpoint with the labels of
#              LABELS (an op2gs-vote point cloud), STEPS iterations; run
#              only when LABELS is set.
# Each count's time per iteration is the median of its steps in the runs'
# train_log.jsonl, the first step of each left out (bench/timing.sh), and
# the speed-up the ratio of the two medians. The summary also gives the
# paired speed-up: the median over iterations of each iteration's 1-thread
# time over its 2-thread time, the two rounds of a pair timing it once with
# each count. The views are decoded before the first iteration, so no step
# waits on a photo.
#
# Environment: DOWNSCALE (1), TRAIN_OPTS (scene options, e.g. "--split
# lerf"), LEARN_OPTS (op2gs-learn's, e.g. "--id-maps object_mask"), STEPS
# (200, half of them on each count), ROUNDS (2; even, so that the views
# are the same for both counts), SCHEDULE (7500), LATE_AT
# (5000), MODEL (an op2gs stage-one work folder with checkpoints/latest.ckpt
# at LATE_AT; without it only the early phase runs), LABELS, PHASES (which
# of the phases to run; default all that MODEL and LABELS allow).
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
steps="${STEPS:-200}"
rounds="${ROUNDS:-2}"
schedule="${SCHEDULE:-7500}"
late_at="${LATE_AT:-5000}"
model="${MODEL:-}"
labels="${LABELS:-}"
bin="$build/stages"
# Odd rounds would time the first count order once more than the other,
# and on a VM whose views differ in cost that order's ratio is not the other's.
[[ "$rounds" =~ ^[0-9]+$ ]] && [ "$rounds" -gt 0 ] && [ $((rounds % 2)) -eq 0 ] ||
  fail "ROUNDS=$rounds: must be a positive even number (each count order as often as the other)"
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

# Runs PHASE with the thread counts alternating (ORDER: 1 2 2 1 or 2 1 1 2),
# in a fresh folder; prints its steps, one "THREADS SECONDS" a line.
run_phase() {  # PHASE LABEL ORDER
  local phase="$1" label="$2" work="$out/run"
  local alternate
  read -r -a alternate <<< "--alternate-threads $3"
  rm -rf "$work"
  case "$phase" in
    early)
      step "$label" "$bin/op2gs-train" "${common[@]}" "$work" "${alternate[@]}" \
        --iterations "$steps" --densify-until 1
      op2gs_steps_by_threads "$work/train_log.jsonl" 1 "$steps"
      ;;
    late)
      resume_in_fresh_folder "$label" "$model/checkpoints/latest.ckpt" "$work" \
        "$bin/op2gs-train" "${common[@]}" "${alternate[@]}" --iterations "$end" \
        --densify-until "$late_at"
      op2gs_steps_by_threads "$work/train_log.jsonl" $((late_at + 1)) "$end"
      ;;
    stage-two)
      step "$label" "$bin/op2gs-learn" "${common[@]}" "$work" "${learn_opts[@]}" \
        "${alternate[@]}" --checkpoint "$model/checkpoints/latest.ckpt" --labels "$labels" \
        --iterations "$end"
      op2gs_steps_by_threads "$work/learn/train_log.jsonl" $((late_at + 1)) "$end"
      ;;
  esac
}

# The median step of one thread count in a file of "THREADS SECONDS" lines.
median_of() {  # FILE THREADS
  awk -v t="$2" '$1 == t { print $2 }' "$1" | median
}

# The median over iterations of each iteration's own speed-up: rounds 2r - 1
# and 2r time the same iterations (line by line) with the counts swapped, so
# each line pair is one iteration, its view and its model, on 1 and on 2
# threads. Less swayed than the ratio of medians by which views fall on
# which count within a round.
paired_speed_up() {  # PHASE
  local phase="$1" round
  for round in $(seq 1 2 "$rounds"); do
    local a="$out/steps_${phase}_round${round}.txt" b="$out/steps_${phase}_round$((round + 1)).txt"
    [ "$(wc -l < "$a")" = "$(wc -l < "$b")" ] || fail "$a, $b: different numbers of steps"
    paste -d ' ' "$a" "$b" | awk -v f="$a" '
      $1 == $3 { print f ": line " NR ": the same thread count in both rounds" > "/dev/stderr"; exit 1 }
      { print ($1 == 1 ? $2 / $4 : $4 / $2) }'
  done | median
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
rm -f "$out"/steps_*.txt  # an earlier invocation's rounds would join this one's summary
for round in $(seq "$rounds"); do
  for phase in "${phases[@]}"; do
    steps_file="$out/steps_${phase}_round${round}.txt"
    order="1 2 2 1"
    [ $((round % 2)) = 0 ] && order="2 1 1 2"
    run_phase "$phase" "${phase}_round${round}" "$order" > "$steps_file"
    one=$(median_of "$steps_file" 1) two=$(median_of "$steps_file" 2)
    echo "round $round ($order), $phase: 1 thread $one s/it, 2 threads $two s/it"
    printf '{"phase":"%s","round":%d,"s_per_iteration_1":%s,"s_per_iteration_2":%s}\n' \
      "$phase" "$round" "$one" "$two" >> "$results"
  done
done
rm -rf "$out/run"

echo
echo "phase      1 thread s/it  2 threads s/it  speed-up (ratio of the medians of all rounds' steps)  paired (median of each iteration's own)"
for phase in "${phases[@]}"; do
  cat "$out"/steps_"${phase}"_round*.txt > "$out/steps_${phase}.txt"
  one=$(median_of "$out/steps_${phase}.txt" 1) two=$(median_of "$out/steps_${phase}.txt" 2)
  paired=$(paired_speed_up "$phase") || fail "$phase: the rounds' steps do not pair up"
  awk -v p="$phase" -v a="$one" -v b="$two" -v c="$paired" \
    'BEGIN { printf "%-10s %14s %15s  %.2fx  %.2fx\n", p, a, b, a / b, c }'
done
