#!/usr/bin/env bash
# The catalogue of bad inputs (docs/reliability.md): every stage, on a tiny
# scene whose work folder holds the outputs of a complete run, is given one
# broken input at a time. Each case asserts:
#   - exit status 1 (2 for a bad option), not a signal, within a time limit;
#   - the last line on stderr names the file and says what is wrong with it
#     (a pattern per case), and nothing else on stderr is a library's own
#     error chatter;
#   - nothing lost: every file of the work folder is byte-identical to before
#     and no file was added (no partial artifact).
# Usage: bad_inputs.sh BIN_DIR [CASE_NAME_PATTERN]
source "$(dirname "${BASH_SOURCE[0]}")/../pipeline/test_lib.sh" "$1"
only="${2:-}"
clip="$root/tests/fixtures/tiny_clip"

echo "-- a tiny scene and a complete run of it"
base="$tmp/base"
"$bin/op2gs-synth" "$base/scene" --views 8 --width 128 --height 96 --supersample 1 --points 600 \
  --test-every 4 > "$tmp/base.log" 2>&1 || fail "op2gs-synth"
"$bin/op2gs-synth" "$base/jpeg" --views 8 --width 128 --height 96 --supersample 1 --points 600 \
  --test-every 4 --as lerf-mask-download >> "$tmp/base.log" 2>&1 || fail "op2gs-synth --as"
s="$base/scene" w="$base/work"
run_base() { "$@" >> "$tmp/base.log" 2>&1 || { tail -5 "$tmp/base.log"; fail "base run: $*"; }; }
run_base "$bin/op2gs-train" "$s" "$w" --iterations 60 --schedule 80 --densify-until 0
run_base "$bin/op2gs-vote" "$s" "$w"
run_base "$bin/op2gs-learn" "$s" "$w" --iterations 80 --schedule 80
run_base "$bin/op2gs-render" "$s" "$w"
run_base "$bin/op2gs-embed" "$s" "$w" --clip "$clip"
run_base "$bin/op2gs-query" "$w" --clip "$clip" --scene "$s"
run_base "$bin/op2gs-eval" "$s" --pred dual-opacity="$w/render/masks" \
  --queries "$w/query/query.json" --out "$w/eval/metrics.json"
run_base "$bin/op2gs-report" --scene s "$s" "$w" --out "$w/report" --no-figures
cp -a "$clip" "$base/clip"

fingerprint() { (cd "$1" && find . -type f -print0 | sort -z | xargs -0 -r sha1sum); }

cases=0 failed=0
# case NAME EXIT PATTERN SETUP COMMAND...: SETUP is shell code run in the
# case's folder (scene/, jpeg/, work/, clip/: copies of the base) before the
# COMMAND, which runs there too.
case_() {
  local name="$1" want="$2" pattern="$3" setup="$4"
  shift 4
  [ -n "$only" ] && [[ "$name" != *$only* ]] && return
  cases=$((cases + 1))
  local c="$tmp/cases/$name"
  mkdir -p "$c"
  cp -a "$base/scene" "$base/jpeg" "$base/work" "$base/clip" "$c/"
  (cd "$c" && eval "$setup") || { echo "FAIL $name: setup failed"; failed=$((failed + 1)); return; }
  local before
  before=$(fingerprint "$c/work")
  local status=0
  (cd "$c" && timeout 120 "$@" > "$c/out.log" 2> "$c/err.log") || status=$?
  local last
  last=$(sed '/^\s*$/d' "$c/err.log" | tail -1 | sed 's/^\[[0-9:]*\] //')
  local why=""
  if [ "$status" -eq 124 ]; then
    why="timed out"
  elif [ "$status" -ge 128 ]; then
    why="killed by signal $((status - 128))"
  elif [ "$status" -ne "$want" ]; then
    why="exit $status, expected $want"
  elif ! grep -Eq -- "$pattern" <<<"$last"; then
    why="last line '$last' does not match '$pattern'"
  elif [ "$want" -eq 1 ] && grep -vq '^\[[0-9:]*\] ' "$c/err.log"; then
    # Every line of a stage's own is time-stamped; anything else is a library's.
    why="library chatter on stderr: $(grep -v '^\[[0-9:]*\] ' "$c/err.log" | head -1 || true)"
  elif [ "$(fingerprint "$c/work")" != "$before" ]; then
    why="the work folder changed: $({ diff <(echo "$before") <(fingerprint "$c/work") || true; } | grep '^[<>]' | head -3 | paste -sd ' ')"
  fi
  if [ -n "$why" ]; then
    echo "FAIL $name: $why"
    failed=$((failed + 1))
  else
    echo "ok   $name: $last"
  fi
  rm -rf "$c"
}

T=("$bin/op2gs-train" scene work --iterations 5 --schedule 5)
V=("$bin/op2gs-vote" scene work)
L=("$bin/op2gs-learn" scene work --iterations 85 --schedule 85)
R=("$bin/op2gs-render" scene work)
E=("$bin/op2gs-embed" scene work --clip clip)
Q=("$bin/op2gs-query" work --clip clip --scene scene)
EV=("$bin/op2gs-eval" scene --pred dual-opacity=work/render/masks --out work/eval/metrics.json)
img=scene/images/frame_00001.png
map=scene/sam2/frame_00001.png
jpg=jpeg/images/frame_00001.jpg
TJ=("$bin/op2gs-train" jpeg work --iterations 5 --schedule 5)

echo "-- images"
case_ image-missing 1 "frame_00001.png.*(not in|no such|missing|cannot)" "rm $img" "${T[@]}"
case_ image-empty 1 "frame_00001.png: " ": > $img" "${T[@]}"
case_ image-truncated-png 1 "frame_00001.png: " "head -c 300 $img > x && mv x $img" "${T[@]}"
case_ image-garbage-png 1 "frame_00001.png: " "echo 'not an image' > $img" "${T[@]}"
case_ image-truncated-jpeg 1 "frame_00001.jpg: " "head -c 400 $jpg > x && mv x $jpg" "${TJ[@]}"
case_ image-garbage-jpeg 1 "frame_00001.jpg: " "head -c 2000 /dev/urandom > $jpg" "${TJ[@]}"
case_ image-wrong-size 1 "frame_00001.png: .*32x24" "oiiotool $img --resize 32x24 -o $img" "${T[@]}"

echo "-- ID maps"
case_ idmap-missing 1 "frame_00001.png: no ID map for training view" "rm $map" "${V[@]}"
case_ idmap-wrong-size 1 "frame_00001.png: .*aspect" "oiiotool $map --resize 64x64 -o $map" "${V[@]}"
case_ idmap-rgb 1 "frame_00001.png: .*channel" "oiiotool $map --ch Y,Y,Y -o $map" "${V[@]}"
case_ idmap-float 1 "frame_00001.png: " "oiiotool $map -d float -o x.exr && mv x.exr $map" "${V[@]}"
case_ idmap-32bit 1 "frame_00001.png: " "oiiotool $map -d uint32 -o x.tif && mv x.tif $map" "${V[@]}"
case_ idmap-truncated 1 "frame_00001.png: " "head -c 100 $map > x && mv x $map" "${V[@]}"
case_ idmap-all-zero 1 "sam2: no training view.s ID map holds an object ID" \
  "for f in scene/sam2/*.png; do oiiotool \$f --mulc 0 -o \$f; done" "${V[@]}"
case_ idmap-names-malformed 1 "objects.json: " "echo '{oops' > scene/sam2/objects.json" "${V[@]}"
case_ idmap-learn-wrong-size 1 "frame_00001.png: .*aspect" "oiiotool $map --resize 64x64 -o $map" "${L[@]}"

echo "-- a segmenter's masks (op2gs-masks)"
M=("$bin/op2gs-masks" masks scene --out work/imported_masks)
one_mask="mkdir -p masks/mug masks/cup && cp $map masks/mug/frame_00001.png"
case_ masks-sizes-differ 1 "mug/frame_00001.png: is 128x96, another mask of its frame" \
  "$one_mask && oiiotool $map --resize 64x48 -o masks/cup/frame_00001.png" "${M[@]}"
case_ masks-name-no-image 1 "masks: cannot tell which object and frame" \
  "mkdir masks && cp $map masks/holiday.png" "${M[@]}"
case_ masks-garbage 1 "cup/frame_00001.png: " \
  "$one_mask && echo 'not an image' > masks/cup/frame_00001.png" "${M[@]}"

echo "-- COLMAP models"
case_ colmap-text-truncated 1 "images.txt: .*missing the line of 2D points" \
  "sed -i '\$d' scene/sparse/0/images.txt" "${T[@]}"
case_ colmap-text-nan 1 "cameras.txt: .*camera parameter" \
  "sed -i 's/^1 PINHOLE \([0-9]*\) \([0-9]*\) [^ ]*/1 PINHOLE \1 \2 nan/' scene/sparse/0/cameras.txt" "${T[@]}"
case_ colmap-unknown-model 1 "cameras.txt: .*FISHEYE_9000" \
  "sed -i 's/^1 PINHOLE/1 FISHEYE_9000/' scene/sparse/0/cameras.txt" "${T[@]}"
case_ colmap-missing-image 1 "nothere.png" \
  "sed -i 's/frame_00002.png/nothere.png/' scene/sparse/0/images.txt" "${T[@]}"
case_ colmap-duplicate-id 1 "images.txt: .*(duplicate|twice)" \
  "awk 'NR>4 && /frame_00002.png/ {sub(/^3 /, \"2 \")} {print}' scene/sparse/0/images.txt > x && mv x scene/sparse/0/images.txt" "${T[@]}"
case_ colmap-binary-truncated 1 "images.bin: " \
  "head -c 100 jpeg/sparse/0/images.bin > x && mv x jpeg/sparse/0/images.bin" "${TJ[@]}"
case_ colmap-binary-garbage 1 "points3D.bin: " \
  "head -c 5000 /dev/urandom > jpeg/sparse/0/points3D.bin" "${TJ[@]}"

echo "-- models and checkpoints"
ply=work/vote/point_cloud.ply
case_ ply-truncated 1 "point_cloud.ply: .*truncated" "head -c 3000 $ply > x && mv x $ply" "${L[@]}"
case_ ply-nan 1 "point_cloud.ply: [0-9]+ of [0-9]+ Gaussians have NaN or infinite" \
  "printf '\\x00\\x00\\xc0\\x7f' | dd of=$ply bs=1 conv=notrunc status=none \
     seek=\$((\$(grep -abo end_header $ply | cut -d: -f1) + 11))" "${L[@]}"
case_ ply-missing-property 1 "point_cloud.ply: .*'label' is missing|point_cloud.ply: .*label" \
  "sed -i 's/property int label/property int lbl/' $ply" "${L[@]}"
case_ ply-wrong-count 1 "point_cloud.ply: .*truncated" \
  "sed -i 's/^element vertex \([0-9]*\)/element vertex 9\1/' $ply" "${L[@]}"
ckpt=work/checkpoints/latest.ckpt
case_ checkpoint-truncated 1 "latest.ckpt: " "head -c 200 $ckpt > x && mv x $ckpt" "${V[@]}"
case_ checkpoint-garbage 1 "latest.ckpt: " "head -c 4000 /dev/urandom > $ckpt" "${V[@]}"
case_ checkpoint-other-version 1 "latest.ckpt: .*version" \
  "printf '\\x63' | dd of=$ckpt bs=1 seek=8 conv=notrunc status=none" "${V[@]}"
case_ checkpoint-learn-truncated 1 "latest.ckpt: " \
  "head -c 500 work/learn/checkpoints/latest.ckpt > x && mv x work/learn/checkpoints/latest.ckpt" "${R[@]}"

echo "-- CLIP, queries, evaluation inputs"
case_ clip-missing 1 "clip.*(model.safetensors|no such|missing|not found)" "rm -r clip" "${E[@]}"
case_ clip-truncated 1 "model.safetensors: " \
  "head -c 1000 clip/model.safetensors > x && mv x clip/model.safetensors" "${E[@]}"
case_ clip-vocab-missing 1 "vocab.json" "rm clip/vocab.json" "${E[@]}"
case_ embeddings-malformed 1 "embeddings.json: " "echo '[1,' > work/embed/embeddings.json" "${Q[@]}"
case_ queries-empty 1 "q.txt: the query list is empty" ": > q.txt && mv q.txt work/q.txt" \
  "$bin/op2gs-query" work --clip clip --queries work/q.txt
case_ query-json-malformed 1 "query.json: " "echo '{\"queries\": 3}' > work/query/query.json" \
  "${EV[@]}" --queries work/query/query.json
case_ test-mask-bad-folder 1 "test_mask/abc: " "mkdir scene/test_mask/abc" "${EV[@]}"
case_ predictions-missing 1 "nothere" "" \
  "$bin/op2gs-eval" scene --pred dual=work/nothere --out work/eval/metrics.json
case_ metrics-malformed 1 "metrics.json: " "echo '{}' > work/eval/metrics.json" \
  "$bin/op2gs-report" --scene s scene work --out work/report --no-figures
case_ viewer-no-stage-two 1 "latest.ckpt: no stage-two checkpoint" "rm -r work/learn" \
  "$bin/op2gs-viewer" scene work
case_ viewer-summary-malformed 1 "summary.json: not valid JSON" "echo '{' > work/vote/summary.json" \
  "$bin/op2gs-viewer" scene work

echo "-- SfM inputs"
npy="scene/poses_bounds.npy"
case_ llff-malformed 1 "poses_bounds.npy: " "echo 'not numpy' > $npy" \
  "$bin/op2gs-sfm" scene work/sfm --llff
case_ transforms-malformed 1 "transforms.json: .*malformed" "echo '{\"frames\": [' > scene/transforms.json" \
  "$bin/op2gs-sfm" scene work/sfm --import scene/transforms.json
case_ transforms-bad-pose 1 "transforms.json: .*transform_matrix" \
  "echo '{\"fl_x\": 50, \"frames\": [{\"file_path\": \"images/frame_00000.png\", \"transform_matrix\": [[1,0,0,0],[0,1,0,\"x\"],[0,0,1,0]]}]}' > scene/transforms.json" \
  "$bin/op2gs-sfm" scene work/sfm --import scene/transforms.json

echo "-- options"
case_ option-train-iterations 2 "iteration -5" "" "$bin/op2gs-train" scene work --iterations -5
case_ option-vote-split 2 "--split" "" "${V[@]}" --split nonsense
case_ option-learn-lambda 2 "lambda|weight" "" "${L[@]}" --lambda-o -1
case_ option-render-views 2 "--views" "" "${R[@]}" --views bogus
case_ option-eval-protocol 2 "--protocol" "" "${EV[@]}" --protocol bogus
case_ option-synth-views 2 "views" "" "$bin/op2gs-synth" newscene --views 1
case_ option-sfm-max-size 2 "maximum image size" "" "$bin/op2gs-sfm" scene work/sfm --max-image-size 10
case_ option-resolution 2 "downscale" "" "${V[@]}" --resolution 3

echo "-- outputs that cannot be written"
case_ output-not-a-folder 1 "work2/run: Not a directory" ": > work2" \
  "$bin/op2gs-train" scene work2/run --iterations 5 --schedule 5

echo "-- what libraries print goes to \$OP2GS_LIBRARY_LOG (the stage log under make)"
c="$tmp/chatter"
mkdir -p "$c"
cp -a "$base/scene" "$base/work" "$c/"
head -c 300 "$c/$img" > "$c/x" && mv "$c/x" "$c/$img"
(cd "$c" && OP2GS_LIBRARY_LOG="$c/libraries.log" "${T[@]}" 2> "$c/err.log") && fail "a truncated PNG trained"
grep -q "^libpng error" "$c/libraries.log" || fail "libpng's message is not in the library log"
! grep -q "^libpng" "$c/err.log" || fail "libpng's message reached the terminal"

echo "$cases cases, $failed failed"
[ "$cases" -ge 40 ] || [ -n "$only" ] || fail "the catalogue has only $cases cases"
[ "$failed" -eq 0 ] || fail "$failed of $cases cases failed"
echo "PASS"
