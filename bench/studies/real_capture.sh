#!/usr/bin/env bash
# A real capture end to end, with exact and with SAM2-like masks side by
# side (docs/benchmarks.md, "Real captures").
#
#   bench/studies/real_capture.sh <build dir> <capture folder> <out dir>
#
# The capture folder is laid out as the Tracebot dataset's scenes are
# (GitHub negarl/Transparent-Object-Pose-Refinement, dataset/scenes/00N):
# rgb/<frame>.png, masks/<scene>_<object>_<instance>_<frame>.png (one binary
# mask per object instance per frame), groundtruth_handeye.txt (id tx ty tz
# qx qy qz qw: camera to world, OpenCV axes) and camera_d435.yaml (the
# intrinsics). Nothing is written into it.
#
# Steps, each with the project's own stages:
#   1. <out>/data/<name>/: a LERF-Mask-layout scene: images/ (links to the
#      photos), transforms.json (the poses, OpenGL axes), every 8th view held
#      out (images_train/ lists the rest), test_mask/<k>/<object>.png (the
#      dataset's masks of the test views), object_mask/ (op2gs-masks on the
#      dataset's masks) and object_mask_<condition>/ (op2gs-mask-errors on
#      those, per condition);
#   2. op2gs-sfm --import transforms.json (COLMAP triangulates the points);
#   3. stage one once (op2gs-train), shared by every condition;
#   4. per condition (exact, sam2like, video) and variant: op2gs-vote, op2gs-learn,
#      op2gs-render, op2gs-eval (oracle mode, LERF-Mask protocol);
#   5. one line per (condition, variant) in <out>/results.jsonl and a
#      per-object table on stdout.
# Any failing step stops the script with its log's tail.
#
# Environment: SFM_OPTS (op2gs-sfm's options; default "--matcher sequential
# --max-image-size 1024": the poses are the robot's, COLMAP only triangulates
# the starting points, and matching each frame with its neighbours on the
# ring takes minutes where matching every pair of 104 frames takes most of
# an hour on 2 cores), ITERATIONS (7500), STAGE_ONE (5000), RESOLUTION (2: the
# photos at 640x360), SEED (of the mask errors, 1), MASK_ERRORS (options of
# op2gs-mask-errors), VARIANTS ("paper": op2gs-learn's options per variant,
# name=options with commas for spaces, e.g. "paper outline=--recipe,robust-outline";
# the bare name "paper" is --recipe paper, the paper's recipe exactly, any
# other bare name op2gs-learn's defaults),
# CONDITIONS ("exact sam2like"; "video" adds the whole-video errors),
# TRAIN_OPTS (op2gs-train's options, e.g. "--recipe fast"), VOTE_OPTS
# (op2gs-vote's options for every variant, e.g. the track remedies
# "--join-switched-ids --find-merges"; name the variants for them, since a
# variant's run folder is <condition>-<name>), RESTART (1: start over;
# otherwise an unfinished stage one or stage two continues from its latest
# checkpoint, a finished stage one is reused, so give each schedule its own
# out dir, and a finished stage two is done again).
set -euo pipefail
build="$(cd "$1" && pwd)"
capture="$(cd "$2" && pwd)"
out="$3"
bin="$build/stages"
iterations="${ITERATIONS:-7500}"
stage_one="${STAGE_ONE:-5000}"
resolution="${RESOLUTION:-2}"
seed="${SEED:-1}"
variants="${VARIANTS:-paper}"
conditions="${CONDITIONS:-exact sam2like}"
read -r -a vote_options <<< "${VOTE_OPTS:-}"
name="$(basename "$capture")"
data="$out/data/$name"
work="$out/work/$name"
mkdir -p "$out" "$work/logs"

fail() { echo "real_capture: $*" >&2; exit 1; }
for f in rgb masks groundtruth_handeye.txt camera_d435.yaml; do
  [ -e "$capture/$f" ] || fail "$capture/$f: missing (not a Tracebot-style capture folder)"
done
# Runs a step with its output in logs/<step>.log; on failure prints its tail and stops.
step() {
  local label="$1"
  shift
  local log="$work/logs/$label.log"
  local start=$SECONDS
  if ! "$@" > "$log" 2>&1; then
    tail -20 "$log" >&2
    fail "step $label failed (log: $log)"
  fi
  echo "  $label: $((SECONDS - start)) s"
}

# Sets `maps` (the ID map folder) and `errors` (op2gs-mask-errors' options)
# of a condition.
condition_maps() {
  # shellcheck disable=SC2206
  case "$1" in
    exact) maps=object_mask errors=() ;;
    sam2like) maps=object_mask_sam2like errors=(${MASK_ERRORS:-}) ;;
    # Fixed before it was measured: the per-view errors at their defaults,
    # each lasting three views, every object's mask systematically tight or
    # loose by up to a tenth of its radius, a quarter of the objects lost
    # while small, and the track errors (docs/synthetic.md).
    video) maps=object_mask_video errors=(--persistence 3 --border-bias 0.1 --lose-small 0.25 --tracks) ;;
    *) fail "unknown condition $1 (exact, sam2like, video)" ;;
  esac
}

# ---------------------------------------------------------------- 1. the scene
if [ ! -f "$data/transforms.json" ]; then
  echo "== $name: the LERF-Mask-layout scene in $data"
  rm -rf "$data"
  mkdir -p "$data/images" "$data/images_train"
  for photo in "$capture"/rgb/*.png; do ln -s "$photo" "$data/images/"; done
  # The intrinsics: camera_matrix [fx 0 cx 0 fy cy 0 0 1], image_width, image_height.
  read -r fx cx fy cy < <(grep camera_matrix "$capture/camera_d435.yaml" | tr -d '[],' |
    awk '{print $2, $4, $6, $7}')
  width=$(awk '/image_width/ {print $2}' "$capture/camera_d435.yaml")
  height=$(awk '/image_height/ {print $2}' "$capture/camera_d435.yaml")
  # The poses: camera to world with OpenCV axes (x right, y down, z forward);
  # transforms.json wants OpenGL axes (y up, z back): the second and third
  # columns of the rotation change sign.
  awk -v fx="$fx" -v fy="$fy" -v cx="$cx" -v cy="$cy" -v w="$width" -v h="$height" '
    BEGIN { printf "{\n  \"camera_model\": \"PINHOLE\", \"fl_x\": %s, \"fl_y\": %s, \"cx\": %s, \"cy\": %s, \"w\": %d, \"h\": %d,\n  \"frames\": [", fx, fy, cx, cy, w, h }
    NF == 8 && $1 !~ /^#/ {
      id = $1; tx = $2; ty = $3; tz = $4; x = $5; y = $6; z = $7; q = $8
      n = sqrt(x*x + y*y + z*z + q*q); x /= n; y /= n; z /= n; q /= n
      r00 = 1 - 2*(y*y + z*z); r01 = 2*(x*y - z*q); r02 = 2*(x*z + y*q)
      r10 = 2*(x*y + z*q); r11 = 1 - 2*(x*x + z*z); r12 = 2*(y*z - x*q)
      r20 = 2*(x*z - y*q); r21 = 2*(y*z + x*q); r22 = 1 - 2*(x*x + y*y)
      printf "%s\n    {\"file_path\": \"images/%06d.png\", \"transform_matrix\": [[%.12f, %.12f, %.12f, %s], [%.12f, %.12f, %.12f, %s], [%.12f, %.12f, %.12f, %s], [0, 0, 0, 1]]}", sep, id, r00, -r01, -r02, tx, r10, -r11, -r12, ty, r20, -r21, -r22, tz
      sep = ","
    }
    END { printf "\n  ]\n}\n" }' "$capture/groundtruth_handeye.txt" > "$data/transforms.json.tmp"
  mapfile -t photos < <(ls "$data/images")
  # Every 8th view (the first of each eight) is a test view, as 3DGS holds out.
  k=0
  for i in "${!photos[@]}"; do
    photo="${photos[$i]}"
    frame="${photo%.png}"
    if ((i % 8 == 0)); then
      mkdir -p "$data/test_mask/$k"
      for mask in "$capture"/masks/*_"$frame".png; do
        [ -e "$mask" ] || continue
        object="$(basename "$mask" "_$frame.png")"
        object="${object#*_}"  # drop the scene number
        # An object out of view has no ground truth (the protocol skips it).
        iinfo --stats "$mask" | grep -q 'Stats Max: 0 ' && continue
        ln -s "$mask" "$data/test_mask/$k/$object.png"
      done
      k=$((k + 1))
    else
      ln -s "$data/images/$photo" "$data/images_train/$photo"
    fi
  done
  step masks "$bin/op2gs-masks" "$capture/masks" "$data" --out "$data/object_mask" \
    --pattern '{*}_{object}_{frame}.png'
  mv "$data/transforms.json.tmp" "$data/transforms.json"
fi
# The masks with errors of each condition, made once from the exact ones.
for condition in $conditions; do
  condition_maps "$condition"
  if [ ! -d "$data/$maps" ]; then
    step "mask-errors-$condition" "$bin/op2gs-mask-errors" "$data/object_mask" \
      "$data/$maps.tmp" --seed "$seed" "${errors[@]}"
    mv "$data/$maps.tmp" "$data/$maps"
    rm -f "$work/stamp.sfm"  # the scene links the ID map folders there are
  fi
done

# ---------------------------------------------------- 2.-3. poses, stage one
scene="$work/sfm/scene"
if [ ! -f "$work/stamp.sfm" ]; then
  echo "== $name: op2gs-sfm --import"
  # shellcheck disable=SC2086
  step sfm "$bin/op2gs-sfm" "$data" "$work/sfm" --import "$data/transforms.json" \
    ${SFM_OPTS:---matcher sequential --max-image-size 1024}
  touch "$work/stamp.sfm"
fi
one="$work/stage-one"
if [ ! -f "$one/metrics.json" ]; then
  # An interrupted stage one (hours at the full schedule) continues from its
  # latest checkpoint (every 1,000 iterations); RESTART=1 starts it over.
  resume=()
  if [ "${RESTART:-0}" != 1 ] && [ -f "$one/checkpoints/latest.ckpt" ]; then
    resume=(--resume)
    echo "== $name: stage one, continuing to $stage_one of $iterations iterations"
  else
    rm -rf "$one"
    echo "== $name: stage one, $stage_one of $iterations iterations"
  fi
  # shellcheck disable=SC2086
  step train "$bin/op2gs-train" "$scene" "$one" "${resume[@]}" --resolution "$resolution" \
    --split lerf --iterations "$stage_one" --schedule "$iterations" ${TRAIN_OPTS:-}
fi

# ------------------------------------------------ 4. conditions and variants
for condition in $conditions; do
  condition_maps "$condition"
  for variant in $variants; do
    label="${variant%%=*}"
    options=()
    [[ "$variant" == *=* ]] && IFS=, read -r -a options <<< "${variant#*=}"
    [ "$variant" = paper ] && options=(--recipe paper)
    run="$work/$condition-$label"
    echo "== $name: $condition masks, $label ${options[*]:-} ${vote_options[*]:-}"
    common=(--resolution "$resolution" --split lerf --id-maps "$maps")
    learn_resume=()
    # A stage two cut off before its end continues from its latest
    # checkpoint; a finished run is done again.
    if [ "${RESTART:-0}" != 1 ] && [ -f "$run/learn/checkpoints/latest.ckpt" ] &&
      [ ! -f "$run/learn/metrics.json" ]; then
      learn_resume=(--resume)
      echo "   continuing its stage two"
    else
      rm -rf "$run"
      cp -r "$one" "$run"
      step "$condition-$label-vote" "$bin/op2gs-vote" "$scene" "$run" "${common[@]}" \
        "${vote_options[@]}"
    fi
    step "$condition-$label-learn" "$bin/op2gs-learn" "$scene" "$run" "${learn_resume[@]}" \
      "${common[@]}" --iterations "$iterations" --schedule "$iterations" "${options[@]}"
    step "$condition-$label-render" "$bin/op2gs-render" "$scene" "$run" --resolution "$resolution" \
      --split lerf
    step "$condition-$label-eval" "$bin/op2gs-eval" "$scene" --protocol lerf \
      --pred dual-opacity="$run/render/masks" --pred baseline="$run/render/baseline_labels" \
      --out "$run/metrics.json"
    rm -rf "$run/checkpoints"
    python3 - "$name" "$condition" "$label" "${options[*]:-}" "${vote_options[*]:-}" "$run" \
      >> "$out/results.jsonl" <<'PY'
import json, sys
name, condition, variant, options, vote_options, run = sys.argv[1:]
m = json.load(open(f"{run}/metrics.json"))["results"]
line = {"capture": name, "condition": condition, "variant": variant, "options": options,
        "vote_options": vote_options}
for k in ("dual-opacity", "baseline"):
    line[k] = {"miou": round(100 * m[k]["miou"], 2), "mbiou": round(100 * m[k]["mbiou"], 2),
               "objects": {q["query"]: [round(100 * q["miou"], 2), round(100 * q["mbiou"], 2)]
                           for q in m[k]["queries"]}}
print(json.dumps(line))
PY
  done
done

# ------------------------------------------------------------- 5. the table
python3 - "$out/results.jsonl" "$name" <<'PY'
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1]) if json.loads(l)["capture"] == sys.argv[2]]
latest = {}
for l in lines:
    latest[(l["condition"], l["variant"])] = l
print(f"| {sys.argv[2]}: masks | variant | object | dual opacity mIoU / mBIoU | baseline mIoU / mBIoU |")
print("| --- | --- | --- | ---: | ---: |")
for (condition, variant), l in latest.items():
    d, b = l["dual-opacity"], l["baseline"]
    print(f"| {condition} | {variant} | **all** | **{d['miou']:.1f} / {d['mbiou']:.1f}** | {b['miou']:.1f} / {b['mbiou']:.1f} |")
    for obj, (mi, mb) in d["objects"].items():
        bi, bb = b["objects"][obj]
        print(f"| | | {obj} | {mi:.1f} / {mb:.1f} | {bi:.1f} / {bb:.1f} |")
PY
