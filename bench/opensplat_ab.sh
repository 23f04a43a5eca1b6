#!/usr/bin/env bash
# op2gs against OpenSplat on the CPU, side by side on one scene, at equal
# Gaussians (docs/benchmarks.md, "op2gs against OpenSplat").
#
#   bench/opensplat_ab.sh <opensplat binary> <op2gs build dir> <scene folder> <out dir>
#
# Two phases, each run ROUNDS times, the two trainers alternated so that the
# machine's drift hits both alike:
#   early  both trainers start from the scene's SfM points (a few thousand
#          large Gaussians) and run STEPS iterations;
#   late   both resume from one trained op2gs stage-one model (MODEL, or
#          trained here to LATE_AT) and run STEPS more iterations.
# Neither densifies or resets opacities inside the timed steps, so both keep
# the same Gaussians. OpenSplat runs its every-step schedule in both phases:
# its densification phase's optimiser cadence (Adam on positions, scales,
# rotations, base colours and opacities every step, on the higher SH
# coefficients every 16 steps), kept to the end by --densify-from and
# --densify-until past the run. In the late phase it also runs its default
# schedule, in which, past densification, Adam steps every parameter only
# every 32 or 64 steps (the gradients summed in between).
# op2gs's time per iteration comes from its train_log.jsonl, OpenSplat's from
# the moments its "Step N" lines appear; each run's median over its steps
# after the first (the first pays for warming up). Both decode every photo
# before their first step, so no timed step waits on a decode.
#
# The scene folder is an op2gs scene with images/ and a COLMAP sparse/0/ (for
# example op2gs-synth's scene, or op2gs-sfm's work/sfm/scene/). OpenSplat
# reads the same images/ and sparse/0/ through a folder of links (a text
# model converted to binary by COLMAP's model_converter).
#
# OpenSplat itself is not part of op2gs: fetch github:WebODM/OpenSplat into a
# temporary folder (never commit it), install Debian's libtorch-dev, and build
#   cmake -S <src> -B <src>/build -G Ninja -DGPU_RUNTIME=CPU -DCMAKE_BUILD_TYPE=Release
#   ninja -C <src>/build opensplat
# Debian's libtorch 1.13 has no zero_grad(bool): in model.cpp replace
# opt->zero_grad(true) by setting each parameter's gradient to an undefined
# tensor (what zero_grad(true) does).
#
# Environment: DOWNSCALE (1; op2gs-train --resolution, OpenSplat -d),
# TRAIN_OPTS (op2gs-train's scene options, e.g. "--split lerf"), STEPS (20),
# ROUNDS (2), SCHEDULE (7500: op2gs's learning-rate schedule), LATE_AT (5000),
# MODEL (an op2gs stage-one work folder trained to LATE_AT with the same
# options: its checkpoints/latest.ckpt and point_cloud/iteration_LATE_AT/).
# Any failing step stops the script with its log's tail.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
# shellcheck source=bench/timing.sh
source "$here/timing.sh"
opensplat="$(realpath "$1")"
build="$(cd "$2" && pwd)"
scene="$(cd "$3" && pwd)"
out="$4"
downscale="${DOWNSCALE:-1}"
read -r -a train_opts <<< "${TRAIN_OPTS:-}"
steps="${STEPS:-20}"
rounds="${ROUNDS:-2}"
schedule="${SCHEDULE:-7500}"
late_at="${LATE_AT:-5000}"
train="$build/stages/op2gs-train"
mkdir -p "$out/logs"
out="$(cd "$out" && pwd)"
logs="$out/logs"

[ -f "$opensplat" ] && [ -x "$opensplat" ] || fail "$opensplat: not an executable file (the OpenSplat binary)"
[ -x "$train" ] || fail "$train: missing (build op2gs first)"
for f in images sparse/0; do
  [ -e "$scene/$f" ] || fail "$scene/$f: missing (an op2gs scene folder: images/, sparse/0/)"
done
# Like step (timing.sh), but each output line prefixed with the moment it appeared.
step_timed() {
  local label="$1"
  shift
  local status=0
  "$@" 2>&1 | while IFS= read -r line; do printf '%s %s\n' "$EPOCHREALTIME" "$line"; done \
    > "$logs/$label.log" || status=$?
  if [ "$status" -ne 0 ]; then
    tail -20 "$logs/$label.log" >&2
    fail "$label failed (log: $logs/$label.log)"
  fi
}

# Seconds per iteration of an OpenSplat run: the median gap between its
# "Step N" lines (so the first step, which ends the loading, is left out).
# Fails unless every step is there.
opensplat_seconds() {
  local log="$1" expected="$2"
  local n
  n=$(awk '/ Step [0-9]*:/ { n++ } END { print n + 0 }' "$log")
  [ "$n" -eq "$expected" ] || fail "$log: $n steps printed, expected $expected"
  grep ' Step [0-9]*:' "$log" | awk 'NR > 1 { print $1 - prev } { prev = $1 }' | median
}

# ------------------------------------------------ OpenSplat's view of the scene
project="$out/opensplat_project"
mkdir -p "$project"
ln -sfn "$scene/images" "$project/images"
# OpenSplat reads COLMAP's binary model only: a text model (op2gs-synth
# writes one) is converted by COLMAP.
if [ -f "$scene/sparse/0/cameras.bin" ]; then
  ln -sfn "$scene/sparse" "$project/sparse"
else
  mkdir -p "$project/sparse/0"
  step colmap_model_converter colmap model_converter --input_path "$scene/sparse/0" \
    --output_path "$project/sparse/0" --output_type BIN
fi
never=100000000  # an iteration neither run reaches: no densification, no resets
opensplat_common=("$project" -d "$downscale" --densify-from "$never" --densify-until "$never")
op2gs_common=("$scene" --resolution "$downscale" "${train_opts[@]}" --schedule "$schedule"
  --no-final-test --checkpoint-every "$never")

# ------------------------------------------------ the late phase's model
model="${MODEL:-$out/model}"
late_ply="$model/point_cloud/iteration_$late_at/point_cloud.ply"
if [ ! -f "$late_ply" ]; then
  [ -z "${MODEL:-}" ] || fail "$late_ply: missing (MODEL must be trained to LATE_AT=$late_at)"
  echo "training the late phase's model to iteration $late_at (op2gs-train)"
  step model "$train" "${op2gs_common[@]}" "$model" --iterations "$late_at" --ply-at "$late_at"
fi
[ -f "$model/checkpoints/latest.ckpt" ] || fail "$model/checkpoints/latest.ckpt: missing"
# OpenSplat resumes from a PLY whose third header line names the iteration.
header='ply
format binary_little_endian 1.0
'
cmp -s -n "${#header}" <(printf '%s' "$header") "$late_ply" || fail "$late_ply: not a binary PLY as op2gs writes it"
{
  printf '%scomment Generated by opensplat at iteration %d\n' "$header" "$late_at"
  tail -c +$((${#header} + 1)) "$late_ply"
} > "$out/late_opensplat.ply"

# ------------------------------------------------ the rounds
results="$out/results.jsonl"
: > "$results"
record() {  # phase trainer schedule round seconds gaussians
  printf '{"phase":"%s","trainer":"%s","schedule":"%s","round":%d,"s_per_iteration":%s,"gaussians":%s}\n' \
    "$@" >> "$results"
}
end=$((late_at + steps))
for round in $(seq "$rounds"); do
  echo "round $round of $rounds"
  # Early: from the SfM points.
  rm -rf "$out/early_op2gs"
  step "early_op2gs_$round" "$train" "${op2gs_common[@]}" "$out/early_op2gs" \
    --iterations "$steps" --densify-until 1
  log="$out/early_op2gs/train_log.jsonl"
  record early op2gs every-step "$round" "$(op2gs_seconds "$log" 1 "$steps")" "$(op2gs_gaussians "$log")"
  step_timed "early_opensplat_$round" "$opensplat" "${opensplat_common[@]}" -n "$steps" \
    -o "$out/early_opensplat.ply"
  record early opensplat every-step "$round" \
    "$(opensplat_seconds "$out/logs/early_opensplat_$round.log" "$steps")" "$(op2gs_gaussians "$log")"

  # Late: from the trained model.
  resume_in_fresh_folder "late_op2gs_$round" "$model/checkpoints/latest.ckpt" "$out/late_op2gs" \
    "$train" "${op2gs_common[@]}" --iterations "$end" --densify-until "$late_at"
  log="$out/late_op2gs/train_log.jsonl"
  record late op2gs every-step "$round" "$(op2gs_seconds "$log" $((late_at + 1)) "$end")" \
    "$(op2gs_gaussians "$log")"
  step_timed "late_opensplat_$round" "$opensplat" "${opensplat_common[@]}" -n "$end" \
    --resume "$out/late_opensplat.ply" -o "$out/late_opensplat_out.ply"
  record late opensplat every-step "$round" \
    "$(opensplat_seconds "$out/logs/late_opensplat_$round.log" "$steps")" "$(op2gs_gaussians "$log")"
  # OpenSplat's default schedule: its densification ends at half the run.
  step_timed "late_opensplat_default_$round" "$opensplat" "$project" -d "$downscale" -n "$end" \
    --resume "$out/late_opensplat.ply" -o "$out/late_opensplat_out.ply"
  record late opensplat default "$round" \
    "$(opensplat_seconds "$out/logs/late_opensplat_default_$round.log" "$steps")" \
    "$(op2gs_gaussians "$log")"
done

# ------------------------------------------------ the table
echo
echo "phase  Gaussians  op2gs s/it  OpenSplat every-step s/it  ratio  OpenSplat default s/it  ratio"
for phase in early late; do
  # The runs' seconds per iteration of one trainer and schedule, or nothing.
  pick() {
    sed -nE "/\"phase\":\"$phase\",\"trainer\":\"$1\",\"schedule\":\"$2\"/ s/.*\"s_per_iteration\":([0-9.e+-]+).*/\1/p" \
      "$results" | paste -sd ' '
  }
  ours=$(pick op2gs every-step) theirs=$(pick opensplat every-step) default=$(pick opensplat default)
  gaussians=$(sed -nE "/\"phase\":\"$phase\"/ { s/.*\"gaussians\":([0-9]+).*/\1/p; q }" "$results")
  m_ours=$(tr ' ' '\n' <<< "$ours" | sed '/^$/d' | median)
  m_theirs=$(tr ' ' '\n' <<< "$theirs" | sed '/^$/d' | median)
  line=$(printf '%-5s  %9s  %s(%s)  %s(%s)  %.1fx' "$phase" "$gaussians" "$m_ours" "$ours" \
    "$m_theirs" "$theirs" "$(echo "$m_theirs / $m_ours" | bc -l)")
  if [ -n "$default" ]; then
    m_default=$(tr ' ' '\n' <<< "$default" | sed '/^$/d' | median)
    line+=$(printf '  %s(%s)  %.1fx' "$m_default" "$default" "$(echo "$m_default / $m_ours" | bc -l)")
  fi
  echo "$line"
done
echo "runs: $results; logs: $out/logs/"
