#!/usr/bin/env bash
# Stage two's iteration against stage one's at the same Gaussians, paired
# (docs/benchmarks.md, "Stage two's cost"): from one stage-one checkpoint and
# one op2gs-vote labelled model, each variant runs STEPS iterations in a
# fresh folder; every round runs the variants in turn, every other round in
# the reverse order, so that the machine's drift hits every variant alike.
#
#   bench/stage_two_cost.sh <op2gs build dir> <scene folder> <voted work folder> <out dir>
#
# The work folder is a stage-one run that op2gs-vote has labelled
# (checkpoints/latest.ckpt, train_log.jsonl and vote/point_cloud.ply), for
# example a run folder of bench/studies/real_capture.sh before its stage two.
#
# Environment: VARIANTS, the first the reference the others are divided by:
# "stage-one" is op2gs-train resumed from the checkpoint (densification
# over), any other "label=options" op2gs-learn with those options (commas
# between words); default "stage-one continued=--lambda-o,0
# paper=--recipe,paper robust-outline=--recipe,robust-outline". TRAIN_OPTS
# (the scene's options, both stages, e.g. "--resolution 2 --split lerf"),
# LEARN_OPTS (op2gs-learn's alone, e.g. "--id-maps object_mask_sam2like"),
# as bench/thread_scaling.sh takes them. STEPS (1000), ROUNDS (2), SCHEDULE
# (30000).
# Each run's time per iteration is the median step of its train_log.jsonl
# after its first 10 (bench/timing.sh); its peak memory is the stage's own
# report. Each run's log and train_log.jsonl stay in OUT/logs/. Any failing
# step stops the script with its log's tail.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
# shellcheck source=bench/timing.sh
source "$here/timing.sh"
[ $# -eq 4 ] || fail "usage: bench/stage_two_cost.sh BUILD SCENE VOTED_WORK OUT"
build="$(cd "$1" && pwd)"
scene="$(cd "$2" && pwd)"
model="$(cd "$3" && pwd)"
out="$4"
read -r -a train_opts <<< "${TRAIN_OPTS:-}"
read -r -a learn_opts <<< "${LEARN_OPTS:-}"
read -r -a variants <<< "${VARIANTS:-stage-one continued=--lambda-o,0 paper=--recipe,paper robust-outline=--recipe,robust-outline}"
steps="${STEPS:-1000}"
rounds="${ROUNDS:-2}"
schedule="${SCHEDULE:-30000}"
bin="$build/stages"
mkdir -p "$out/logs"
out="$(cd "$out" && pwd)"
logs="$out/logs"

for stage in op2gs-train op2gs-learn; do
  [ -x "$bin/$stage" ] || fail "$bin/$stage: missing (build op2gs first)"
done
checkpoint="$model/checkpoints/latest.ckpt"
labels="$model/vote/point_cloud.ply"
[ -f "$checkpoint" ] || fail "$checkpoint: missing (the work folder must hold a stage-one checkpoint)"
[ -f "$labels" ] || fail "$labels: missing (run op2gs-vote on the work folder first)"
[ -f "$model/train_log.jsonl" ] || fail "$model/train_log.jsonl: missing (a stage-one work folder has it)"
start=$(tail -1 "$model/train_log.jsonl" | sed -E 's/.*"iteration":([0-9]+).*/\1/')
[[ "$start" =~ ^[0-9]+$ ]] || fail "$model/train_log.jsonl: no iteration in its last line"
end=$((start + steps))
[ "$steps" -gt 20 ] || fail "STEPS: $steps is too few (at least 21: the first 10 are left out)"

common=("$scene" "${train_opts[@]}" --iterations "$end" --schedule "$schedule" --no-final-test
  --checkpoint-every 100000000)

# Runs one variant in a fresh folder; prints "seconds-per-iteration peak-MiB".
run_variant() {  # VARIANT LABEL
  local variant="$1" label="$2" work="$out/run" options=() log
  [[ "$variant" == *=* ]] && IFS=, read -r -a options <<< "${variant#*=}"
  if [ "${variant%%=*}" = stage-one ]; then
    resume_in_fresh_folder "$label" "$checkpoint" "$work" "$bin/op2gs-train" "${common[@]}" \
      --densify-until "$start" "${options[@]}"
    log="$work/train_log.jsonl"
  else
    rm -rf "$work"
    step "$label" "$bin/op2gs-learn" "${common[@]}" "$work" "${learn_opts[@]}" \
      --checkpoint "$checkpoint" --labels "$labels" "${options[@]}"
    log="$work/learn/train_log.jsonl"
  fi
  cp "$log" "$logs/$label.train_log.jsonl"  # for the drift within a run
  local seconds mib
  seconds="$(op2gs_seconds "$log" $((start + 10)) "$end")"
  mib=$(sed -nE 's/.*peak memory ([0-9]+) MiB.*/\1/p' "$logs/$label.log" | tail -1)
  [ -n "$mib" ] || fail "$logs/$label.log: no peak memory reported"
  echo "$seconds $mib"
}

results="$out/results.jsonl"
: > "$results"
for round in $(seq "$rounds"); do
  order=("${variants[@]}")
  if [ $((round % 2)) = 0 ]; then
    order=()
    for ((i = ${#variants[@]} - 1; i >= 0; i--)); do order+=("${variants[$i]}"); done
  fi
  for variant in "${order[@]}"; do
    name="${variant%%=*}"
    timing="$(run_variant "$variant" "round${round}_$name")"  # a failed run stops the script here
    read -r seconds mib <<< "$timing"
    echo "round $round, $name: $seconds s/it, peak $mib MiB"
    printf '{"variant":"%s","round":%d,"s_per_iteration":%s,"peak_mib":%s}\n' \
      "$name" "$round" "$seconds" "$mib" >> "$results"
  done
done
rm -rf "$out/run"

pick() {  # VARIANT FIELD
  sed -nE "/\"variant\":\"$1\",/ s/.*\"$2\":([0-9.e+-]+).*/\1/p" "$results"
}
reference="${variants[0]%%=*}"
base=$(pick "$reference" s_per_iteration | median)
echo
echo "from iteration $start, $steps iterations, $(op2gs_gaussians "$model/train_log.jsonl") Gaussians"
echo "variant          s/it (median)  against $reference  peak MiB (largest)"
for variant in "${variants[@]}"; do
  name="${variant%%=*}"
  s=$(pick "$name" s_per_iteration | median)
  mib=$(pick "$name" peak_mib | sort -g | tail -1)
  awk -v n="$name" -v s="$s" -v b="$base" -v m="$mib" \
    'BEGIN { printf "%-16s %13.4f  %10.2fx  %17d\n", n, s, s / b, m }'
done
