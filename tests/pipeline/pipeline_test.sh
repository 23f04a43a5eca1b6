#!/usr/bin/env bash
# pipeline/Makefile end to end: a tiny synthetic scene through every stage
# (SfM included), artifacts and metrics checked; a second make does nothing;
# a changed stage option reruns that stage and those after it only; the
# dataset definitions against folders that mimic LERF-Mask and 3DOVS; a scene
# that lacks its ID maps fails its stage while the other scenes of a -k run
# go on; a scene whose own COLMAP model has distortion is undistorted.
# Usage: pipeline_test.sh BIN_DIR
source "$(dirname "${BASH_SOURCE[0]}")/test_lib.sh" "$1"

tiny=(DATASET=synthetic WORK_ROOT="$tmp/run" SYNTH_OPTS="--supersample 1 --points 1500"
      ITERATIONS=300 STAGE_ONE=200 TRAIN_OPTS="--densify-from 50 --densify-until 150 --densify-every 50")

echo "-- every stage of a tiny synthetic scene"
mk "${tiny[@]}" > "$tmp/first.log" 2>&1 || { tail -40 "$tmp/first.log"; fail "the tiny run failed"; }
w="$tmp/run/demo"
# A new work folder has no lock record yet: its first run says nothing of it.
! grep -q "lock.sh" "$tmp/first.log" || fail "the first run printed an error of pipeline/lock.sh"
for f in sfm/scene/sparse/0/images.bin checkpoints/latest.ckpt vote/point_cloud.ply \
         learn/checkpoints/latest.ckpt render/masks render/rgb render/instance_labels \
         embed/embeddings.json query/query.json eval/metrics.json report/report.html \
         report/report.md logs/train.log logs/learn.log; do
  [ -e "$w/$f" ] || fail "missing artifact $w/$f"
done
[ -s "$tmp/run/report/report.html" ] || fail "no dataset report"
grep -q "report: $tmp/run/report/report.html" "$tmp/first.log" || fail "the run did not say where the report is"
# The demo answers its queries with the tests' tiny CLIP: query mode is marked
# not available, with the reason, instead of scored.
grep -q '"available": false' "$w/eval/metrics.json" || fail "metrics.json scores the tiny CLIP's answers"
! grep -q '"query_results"' "$w/eval/metrics.json" || fail "metrics.json has query-mode scores of the tiny CLIP"
grep -q "^Query mode: not available" "$tmp/first.log" || fail "the headline does not say query mode is not available"
# COLMAP's OPENCV cameras were undistorted: masks are scored in the photos' geometry.
grep -q '"mask_geometry": "photos' "$w/eval/metrics.json" || fail "masks not scored in the photos' geometry"
# ... and the masks are also written over the photos (PHOTO_GEOMETRY=auto).
ls "$w/render/photo/masks/"*/*.png >/dev/null 2>&1 || fail "no masks in the photos' geometry"
# The metrics file parses: op2gs-report reads every figure of it.
"$bin/op2gs-report" --scene demo "$w/sfm/scene" "$w" --out "$tmp/check" --no-figures >/dev/null 2>&1 ||
  fail "metrics.json does not parse"
grep -q "dual-opacity (query) mIoU" "$tmp/check/report.md" || fail "no query-mode row in the report"
grep -q "| n/a | n/a |" "$tmp/check/report.md" || fail "the report's query columns are not marked n/a"
# A dataset report takes --scene once per scene (LERF-Mask's three, 3DOVS's ten).
"$bin/op2gs-report" --scene demo "$w/sfm/scene" "$w" --scene again "$w/sfm/scene" "$w" \
  --out "$tmp/check2" --no-figures --no-viewer >/dev/null 2>&1 || fail "op2gs-report refuses two scenes"
grep -q "^| demo |" "$tmp/check2/report.md" && grep -q "^| again |" "$tmp/check2/report.md" ||
  fail "the two-scene report lacks a scene's row"

echo "-- options given beside op2gs-train's --recipe keep their values"
"$bin/op2gs-train" "$w/sfm/scene" "$tmp/given" --recipe fast --half-views-from 0 \
  --position-lr-hold-until 7 --iterations 2 --no-final-test > "$tmp/given.log" 2>&1 ||
  { tail -20 "$tmp/given.log"; fail "op2gs-train --recipe fast with options failed"; }
m="$tmp/given/metrics.json"
grep -q '"sparse_adam": true' "$m" || fail "--recipe fast did not set sparse Adam ($m)"
! grep -q '"half_views_from"' "$m" || fail "--half-views-from 0 lost to --recipe fast ($m)"
grep -q '"position_lr_hold_until": 7' "$m" || fail "--position-lr-hold-until lost to --recipe fast ($m)"
"$bin/op2gs-train" "$w/sfm/scene" "$tmp/given2" --recipe fast --no-sparse-adam --iterations 2 \
  --no-final-test > "$tmp/given2.log" 2>&1 ||
  { tail -20 "$tmp/given2.log"; fail "op2gs-train --recipe fast --no-sparse-adam failed"; }
m="$tmp/given2/metrics.json"
! grep -q '"sparse_adam"' "$m" || fail "--no-sparse-adam lost to --recipe fast ($m)"
grep -q '"half_views_from"' "$m" || fail "--recipe fast set no half views ($m)"

echo "-- op2gs-train --max-gaussians: densification adds none beyond the budget"
"$bin/op2gs-train" "$w/sfm/scene" "$tmp/budget" --max-gaussians 1 --densify-from 20 \
  --densify-every 20 --densify-until 100 --iterations 100 --no-final-test > "$tmp/budget.log" 2>&1 ||
  { tail -20 "$tmp/budget.log"; fail "op2gs-train --max-gaussians failed"; }
grep -q '"max_gaussians": 1' "$tmp/budget/metrics.json" || fail "metrics.json lacks the budget"
log="$tmp/budget/train_log.jsonl"
grep -q '"held_back"' "$log" || fail "the budget held back no candidate ($log)"
counts=$(grep -o '"gaussians":[0-9]*' "$log" | cut -d: -f2)
[ "$(echo "$counts" | sort -n | tail -1)" = "$(echo "$counts" | head -1)" ] ||
  fail "the Gaussians grew past the count the budget found ($log)"

echo "-- a second make does nothing"
mk "${tiny[@]}" -q || fail "make -q says something is stale"
mk "${tiny[@]}" | grep "Nothing to be done" > /dev/null || fail "a second make did work"

echo "-- a changed stage-two option reruns stage two and what follows, only"
stamps() { for s in generate sfm train vote learn render embed query eval report; do
  echo "$s $(stat -c %Y.%y "$w/stamps/$s.done")"; done; }
before=$(stamps)
sleep 1.1
# LEARN_OPTS's --recipe comes after the one RECIPE gives, and wins.
mk "${tiny[@]}" LEARN_OPTS="--lambda-o 0.2 --recipe paper" > "$tmp/second.log" 2>&1 ||
  { tail -40 "$tmp/second.log"; fail "rerun failed"; }
grep -q '"pixel_loss": "cross-entropy"' "$w/learn/metrics.json" ||
  fail "LEARN_OPTS=--recipe paper did not override the default object loss"
after=$(stamps)
for s in generate sfm train vote; do
  [ "$(grep "^$s " <<<"$before")" = "$(grep "^$s " <<<"$after")" ] || fail "stage $s reran"
done
for s in learn render embed query eval report; do
  [ "$(grep "^$s " <<<"$before")" != "$(grep "^$s " <<<"$after")" ] || fail "stage $s did not rerun"
done

echo "-- the dataset definitions against LERF-Mask and 3DOVS layouts"
png=$(find "$tmp/run/data/demo/sam2" -name '*.png' | head -1)
"$root/tests/pipeline/make_fixtures.sh" "$png" "$tmp/fx"
mk DATASET=lerf-mask DATA_ROOT="$tmp/fx/lerf_mask" WORK_ROOT="$tmp/lerf" check > "$tmp/check.log" 2>&1 ||
  { cat "$tmp/check.log"; fail "LERF-Mask fixture does not check"; }
grep -q "figurines: 3 test views, 7 queries" "$tmp/check.log" || fail "figurines not checked"
mk DATASET=3dovs DATA_ROOT="$tmp/fx/3dovs" WORK_ROOT="$tmp/ovs" check > "$tmp/check.log" 2>&1 ||
  { cat "$tmp/check.log"; fail "3DOVS fixture does not check"; }
grep -q "covered_desk: 5 segmented views, 6 classes" "$tmp/check.log" || fail "3DOVS scenes not checked"
# The commands the definitions give.
mk DATASET=lerf-mask DATA_ROOT="$tmp/fx/lerf_mask" WORK_ROOT="$tmp/lerf" -n figurines.query |
  grep -- "--queries $tmp/lerf/figurines/options/queries.txt" > /dev/null ||
  fail "LERF-Mask queries not used"
[ "$(wc -l < "$tmp/lerf/figurines/options/queries.txt")" -eq 7 ] || fail "figurines query list"
grep -qx "rubber duck with red hat" "$tmp/lerf/figurines/options/queries.txt" || fail "query text"
mk DATASET=3dovs DATA_ROOT="$tmp/fx/3dovs" WORK_ROOT="$tmp/ovs" -n bed.sfm | grep -- "--llff" > /dev/null ||
  fail "3DOVS SfM does not keep the LLFF cameras"
mk DATASET=3dovs DATA_ROOT="$tmp/fx/3dovs" WORK_ROOT="$tmp/ovs" -n bed.eval |
  grep -- "--protocol 3dovs-lerf" > /dev/null || fail "3DOVS protocol"
# Each recipe reaches both training stages: by default the paper's stage one
# and op2gs-learn's robust-outline; RECIPE=paper is the paper's recipe in
# both; RECIPE=fast the fast stage one and sparse Adam in stage two.
recipe_of() {
  mk DATASET=lerf-mask DATA_ROOT="$tmp/fx/lerf_mask" WORK_ROOT="$tmp/lerf" "$@" -n figurines.learn \
    > "$tmp/recipe.log" || { cat "$tmp/recipe.log"; fail "make -n with $*"; }
}
expect() { grep -q -- "$1" "$tmp/recipe.log" || { cat "$tmp/recipe.log"; fail "$2"; }; }
recipe_of
expect "op2gs-train.*--recipe paper" "the default recipe: op2gs-train"
expect "op2gs-learn.*--recipe robust-outline" "the default recipe: op2gs-learn"
recipe_of RECIPE=paper
expect "op2gs-train.*--recipe paper" "RECIPE=paper: op2gs-train"
expect "op2gs-learn.*--recipe paper" "RECIPE=paper: op2gs-learn"
recipe_of RECIPE=fast
expect "op2gs-train.*--recipe fast" "RECIPE=fast: op2gs-train"
expect "op2gs-learn.*--recipe robust-outline --sparse-adam --half-views-from 1" "RECIPE=fast: op2gs-learn"
if mk DATASET=lerf-mask DATA_ROOT="$tmp/fx/lerf_mask" WORK_ROOT="$tmp/lerf" RECIPE=papr \
  -n figurines.learn > "$tmp/recipe.log" 2>&1; then
  fail "RECIPE=papr was accepted"
fi
grep -q "RECIPE=papr: default, paper or fast" "$tmp/recipe.log" || { cat "$tmp/recipe.log"; fail "RECIPE=papr's error"; }
# Without the CLIP files a run still evaluates oracle mode, saying why query
# mode is n/a, and neither embeds nor queries.
mk DATASET=lerf-mask DATA_ROOT="$tmp/fx/lerf_mask" WORK_ROOT="$tmp/lerf" CLIP="$tmp/no-clip" \
  -n figurines.eval > "$tmp/noclip.log"
grep -q -- "--query-unavailable \"no CLIP files in $tmp/no-clip\"" "$tmp/noclip.log" ||
  { cat "$tmp/noclip.log"; fail "a run without CLIP does not say why query mode is n/a"; }
! grep -q "op2gs-embed\|op2gs-query\|--queries" "$tmp/noclip.log" ||
  fail "a run without CLIP still embeds or queries"
# A scene whose ground truth lost a query fails the check, naming it.
rm "$tmp"/fx/lerf_mask/ramen/test_mask/*/egg.png
if mk DATASET=lerf-mask DATA_ROOT="$tmp/fx/lerf_mask" WORK_ROOT="$tmp/lerf" check > "$tmp/check.log" 2>&1; then
  fail "a missing query passed the check"
fi
grep -q "ramen/test_mask: queries differ from the dataset's list: missing: egg" "$tmp/check.log" ||
  { cat "$tmp/check.log"; fail "the check did not name the missing query"; }

echo "-- photos: a scene without ID maps fails its stage and the others go on (-k);"
echo "   a scene's own COLMAP model with distortion is undistorted before training,"
echo "   its masks are also written in the photos' geometry, and the run ends with"
echo "   the 3D viewer"
for s in a b c; do
  "$bin/op2gs-synth" "$tmp/photos/$s" --views 8 --width 96 --height 72 --supersample 1 \
    --points 500 >/dev/null 2>&1
done
rm -rf "$tmp/photos/b/sam2"
sed -i 's/^1 PINHOLE \(.*\)$/1 OPENCV \1 -0.05 0.01 0 0/' "$tmp/photos/c/sparse/0/cameras.txt"
grep -q "^1 OPENCV" "$tmp/photos/c/sparse/0/cameras.txt" || fail "could not give scene c distortion"
photos=(DATASET=photos DATA_ROOT="$tmp/photos" WORK_ROOT="$tmp/prun" ITERATIONS=100 STAGE_ONE=80)
if mk "${photos[@]}" -k vote > "$tmp/k.log" 2>&1; then fail "a scene without sam2/ passed"; fi
[ -e "$tmp/prun/a/stamps/vote.done" ] || { tail -30 "$tmp/k.log"; fail "scene a did not finish"; }
[ ! -e "$tmp/prun/b/stamps/vote.done" ] || fail "scene b's vote passed"
[ -e "$tmp/prun/c/stamps/vote.done" ] || { tail -30 "$tmp/k.log"; fail "scene c (OPENCV model) did not finish"; }
grep -q "sam2/: 8 ID maps undistorted" "$tmp/prun/c/logs/sfm.log" || fail "scene c's ID maps were not undistorted"
[ -L "$tmp/prun/a/sfm/scene/sam2" ] || fail "scene a's ID maps were resampled, though its cameras are pinholes"
grep -q "$tmp/photos/b: no ID map folder: looked for .*sam2/" "$tmp/prun/b/logs/sfm.log" ||
  fail "op2gs-sfm did not warn that scene b has no ID maps"
grep -q "op2gs: b: stage vote failed (exit 1): .*/b/sfm/scene: no ID map folder" "$tmp/k.log" ||
  { tail -30 "$tmp/k.log"; fail "no clear failure line"; }
grep "op2gs: b: stage vote failed" "$tmp/k.log"
# Scene c's photos were undistorted: its masks are also written over the
# photos themselves; scene a's views are its photos, so it has no photo/.
mk "${photos[@]}" a.render c.render > "$tmp/r.log" 2>&1 || { tail -30 "$tmp/r.log"; fail "photos render"; }
ls "$tmp/prun/c/render/photo/masks/"*/*.png >/dev/null 2>&1 || fail "scene c has no photo-geometry masks"
[ ! -e "$tmp/prun/a/render/photo" ] || fail "scene a has photo-geometry masks, though its views are its photos"
# A photos run ends with the 3D viewer (no report: there is nothing to score
# against), its objects named from the ID maps' objects.json.
mk "${photos[@]}" a.viewer > "$tmp/v.log" 2>&1 || { tail -30 "$tmp/v.log"; fail "photos viewer"; }
for f in index.html viewer.js model.spz gaussians.bin model.ply scene.json ../vendor.min.js; do
  [ -s "$tmp/prun/a/viewer/a/$f" ] || fail "the photos run has no viewer/a/$f"
done
grep -q '"name": "red ball"' "$tmp/prun/a/viewer/a/scene.json" ||
  fail "the viewer does not name the objects of sam2/objects.json"
[ ! -e "$tmp/prun/a/report" ] || fail "a photos run wrote a report"
echo "PASS"
