#!/usr/bin/env bash
# The real-capture study (docs/benchmarks.md, "Real-capture imperfections"):
# for each condition and seed, a synthetic scene made with op2gs-synth's
# capture options, stage one on the stage-two benchmark's schedule (scaled
# down by SCALE, default 4: 7,500 iterations), then for each variant voting,
# stage two, rendering and op2gs-eval in oracle mode. One line of JSON per
# (condition, seed, variant) is appended to <out>/results.jsonl with test
# PSNR (and the colour-fitted right-half PSNR), baseline and dual-opacity
# mIoU / mBIoU and their per-object IoU, and op2gs-floaters' figures.
#
#   bench/studies/capture_study.sh <build dir> <out dir> <seeds> <condition>...
#
# A condition is a name and op2gs-synth options, name=options with commas for
# spaces: clean=  exposure=--exposure,0.25,--white-balance,0.03
# Variants (VARIANTS, default "plain"), each the paper's recipe (op2gs-learn
# --recipe paper) with the change its name says: plain (none), robust
# (op2gs-learn --recipe robust: the generalized cross-entropy),
# robust-outline (op2gs-learn --recipe robust-outline, op2gs-learn's
# default), robust-outline-q-<q> (the same with --outline-q <q>), joined
# (op2gs-vote --join-switched-ids), tracks (and --find-merges), exposure
# (op2gs-train --exposure-compensation), exposure+joined, exposure+tracks; and for the sensitivity study,
# one value changed from the paper's: lambda-<lambda_o>, m-<M>, tau-<tau>,
# init-<sigma* of every Gaussian at the start of stage two>; and for the
# spread of stage two alone, plain-seed-<n> (op2gs-learn --seed n: another
# order of the views, other objects sampled), and robust-seed-<n> and
# robust-outline-seed-<n> the same for --recipe robust and robust-outline.
# Pose variants:
# fit (op2gs-render --fit-poses: the test views' cameras fitted to their
# photos), poses (and op2gs-train --refine-poses), poses+tracks,
# exposure+poses+tracks. The fast recipe: fast (op2gs-train --recipe fast,
# op2gs-learn --sparse-adam --half-views-from 1); dash (op2gs-train --recipe
# dash, an experiment, stage two as fast's, with stage one's position learning
# rate's hold). Any variant followed by +protect-<share> (or
# protect-<share> alone, for plain) also protects the sigma* of Gaussians whose
# votes agree at least that much (op2gs-learn --protect-agreement).
# At the end, op2gs-report writes <out>/report/ (report.html, report.md) with
# one section per (condition, seed, variant) measured so far in <out>: test
# PSNR and the colour-fitted PSNR, baseline and dual-opacity scores per
# object, and the floater tables.
# Environment: SCALE (schedule divisor), SYNTH (extra op2gs-synth options for
# every condition, e.g. "--width 640 --height 480 --views 60"), FIT_STEPS
# (steps of each test view's pose fit, default 100).
set -euo pipefail
# shellcheck source=bench/timing.sh
source "$(dirname "$0")/../timing.sh"  # stage_one_hold
build="$(cd "$1" && pwd)"
out="$2"
seeds="$3"
shift 3
scale="${SCALE:-4}"
variants="${VARIANTS:-plain}"
fit_steps="${FIT_STEPS:-100}"
total=$((30000 / scale))
stage_one=$((20000 / scale))
densify_until=$((15000 / scale))
bin="$build/stages"
mkdir -p "$out"
# Runs a stage and shows only its result lines; a failing stage prints its
# log's tail and stops the study.
quiet() {
  local log
  log="$(mktemp)"
  if ! "$@" > "$log" 2>&1; then
    tail -20 "$log" >&2
    rm -f "$log"
    echo "capture_study: failed: $*" >&2
    exit 1
  fi
  # grep's status 1 means no such line, which is fine; 2 is an error.
  tr '\r' '\n' < "$log" | grep -v '^\[[#-]' | grep -E 'PSNR|joined|error|Error' || [ $? -eq 1 ]
  rm -f "$log"
}

for condition in "$@"; do
  name="${condition%%=*}"
  options="${condition#*=}"
  for seed in $seeds; do
    dir="$out/$name-$seed"
    mkdir -p "$dir"
    # shellcheck disable=SC2086
    [ -d "$dir/scene" ] || "$bin/op2gs-synth" "$dir/scene" --seed "$seed" ${SYNTH:-} ${options//,/ } \
      > "$dir/synth.log" 2>&1
    for variant in $variants; do
      train_options=() vote_options=() learn_options=() render_options=()
      recipe="$variant" protect="" object_loss=paper
      if [[ "$recipe" == protect-* ]]; then
        protect="${recipe#protect-}" recipe=plain
      elif [[ "$recipe" == *+protect-* ]]; then
        protect="${recipe##*+protect-}" recipe="${recipe%+protect-*}"
      fi
      case "$recipe" in
        plain) ;;
        robust) object_loss=robust ;;
        robust-outline) object_loss=robust-outline ;;
        fast)
          train_options=(--recipe fast)
          learn_options=(--sparse-adam --half-views-from 1)
          ;;
        dash)
          train_options=(--recipe dash)
          learn_options=(--sparse-adam --half-views-from 1)
          ;;
        lambda-*) learn_options=(--lambda-o "${variant#lambda-}") ;;
        m-*) learn_options=(--objects-per-step "${variant#m-}") ;;
        tau-*) render_options=(--tau "${variant#tau-}") ;;
        init-*) learn_options=(--sigma-star-init "${variant#init-}") ;;
        plain-seed-*) learn_options=(--seed "${variant#plain-seed-}") ;;
        robust-seed-*)
          object_loss=robust
          learn_options=(--seed "${variant#robust-seed-}")
          ;;
        robust-outline-q-*)
          object_loss=robust-outline
          learn_options=(--outline-q "${variant#robust-outline-q-}")
          ;;
        robust-outline-seed-*)
          object_loss=robust-outline
          learn_options=(--seed "${variant#robust-outline-seed-}")
          ;;
        joined) vote_options=(--join-switched-ids) ;;
        exposure) train_options=(--exposure-compensation) ;;
        exposure+joined)
          train_options=(--exposure-compensation)
          vote_options=(--join-switched-ids)
          ;;
        tracks) vote_options=(--join-switched-ids --find-merges) ;;
        exposure+tracks)
          train_options=(--exposure-compensation)
          vote_options=(--join-switched-ids --find-merges)
          ;;
        fit)
          learn_options=(--fit-test-poses "$fit_steps")
          render_options=(--fit-poses "$fit_steps")
          ;;
        poses)
          train_options=(--refine-poses)
          learn_options=(--fit-test-poses "$fit_steps")
          render_options=(--fit-poses "$fit_steps")
          ;;
        poses+tracks)
          train_options=(--refine-poses)
          vote_options=(--join-switched-ids --find-merges)
          learn_options=(--fit-test-poses "$fit_steps")
          render_options=(--fit-poses "$fit_steps")
          ;;
        exposure+poses+tracks)
          train_options=(--exposure-compensation --refine-poses)
          vote_options=(--join-switched-ids --find-merges)
          learn_options=(--fit-test-poses "$fit_steps")
          render_options=(--fit-poses "$fit_steps")
          ;;
        *) echo "unknown variant $variant" >&2; exit 2 ;;
      esac
      learn_options+=(--recipe "$object_loss")
      [ -n "$protect" ] && learn_options+=(--protect-agreement "$protect")
      # Variants that train alike share stage one.
      suffix=""
      [[ " ${train_options[*]:-} " == *" --exposure-compensation "* ]] && suffix+="-exposure"
      [[ " ${train_options[*]:-} " == *" --refine-poses "* ]] && suffix+="-poses"
      [[ " ${train_options[*]:-} " == *" --recipe fast "* ]] && suffix+="-fast"
      [[ " ${train_options[*]:-} " == *" --recipe dash "* ]] && suffix+="-dash"
      one="$dir/stage-one$suffix"
      if [ ! -f "$one/metrics.json" ]; then
        echo "== $name seed $seed: stage one ${train_options[*]:-}"
        quiet "$bin/op2gs-train" "$dir/scene" "$one" --iterations "$stage_one" --schedule "$total" \
          --densify-until "$densify_until" "${train_options[@]}"
      fi
      work="$dir/$variant"
      rm -rf "$work"
      echo "== $name seed $seed: $variant"
      if [[ "$variant" == tau-* && -f "$dir/plain/learn/metrics.json" ]]; then
        # Only the mask threshold differs: the plain run's stage two serves.
        mkdir -p "$work"
        cp -r "$dir/plain/learn" "$dir/plain/vote" "$one/metrics.json" "$work/"
      else
        cp -r "$one" "$work"
        quiet "$bin/op2gs-vote" "$dir/scene" "$work" "${vote_options[@]}"
        # Stage two goes on with the position learning rate's hold stage one
        # ran with (op2gs-train --recipe dash sets one; 0 otherwise).
        quiet "$bin/op2gs-learn" "$dir/scene" "$work" --iterations "$total" --schedule "$total" \
          "${learn_options[@]}" --position-lr-hold-until "$(stage_one_hold "$one")"
      fi
      quiet "$bin/op2gs-render" "$dir/scene" "$work" "${render_options[@]}"
      quiet "$bin/op2gs-eval" "$dir/scene" --pred dual-opacity="$work/render/masks" \
        --pred baseline="$work/render/baseline_labels" --out "$work/metrics.json"
      quiet "$bin/op2gs-floaters" "$dir/scene" "$work"
      python3 - "$name" "$seed" "$variant" "$work" "$one" >> "$out/results.jsonl" <<'PY'
import json, sys
name, seed, variant, work, one = sys.argv[1:]
m = json.load(open(f"{work}/metrics.json"))["results"]
def objects(r):
    return {q["query"]: round(100 * q["miou"], 2) for q in r["queries"]}
line = {
    "condition": name, "seed": int(seed), "variant": variant,
    "psnr_stage_one": json.load(open(f"{one}/metrics.json"))["psnr"],
    "psnr": json.load(open(f"{work}/learn/metrics.json"))["psnr"],
    "psnr_fitted": json.load(open(f"{work}/learn/metrics.json")).get("psnr_fitted_right_half"),
}
f = json.load(open(f"{work}/floaters.json"))
line["floaters"] = {
    "share": f["floater_share"], "region": f["region"]["floaters"],
    "opacity_share": f["floater_opacity_share"],
    "region_opacity_share": f["region"]["floater_opacity_share"],
    "mask_wrong_share": f["mask_wrong_share"], "mask_floater_share": f["mask_floater_share"]}
for k in ("dual-opacity", "baseline"):
    line[k] = {"miou": round(100 * m[k]["miou"], 2), "mbiou": round(100 * m[k]["mbiou"], 2),
               "objects": objects(m[k])}
print(json.dumps(line))
PY
      tail -1 "$out/results.jsonl" | python3 -c "
import json,sys; l=json.loads(sys.stdin.read())
print(f\"   {l['condition']} {l['seed']} {l['variant']}: dual {l['dual-opacity']['miou']:.1f} baseline {l['baseline']['miou']:.1f} PSNR {l['psnr']:.2f}\")"
      rm -rf "$work/checkpoints"
    done
  done
done

# The study's section of the report: every run in <out>, condition by seed by variant.
report_scenes=()
for metrics in "$out"/*/*/metrics.json; do
  [ -f "$metrics" ] || continue
  work="$(dirname "$metrics")"
  dir="$(dirname "$work")"
  [[ "$(basename "$work")" == stage-one* ]] && continue  # training metrics, not scores
  report_scenes+=(--scene "$(basename "$dir") $(basename "$work")" "$dir/scene" "$work")
done
if [ ${#report_scenes[@]} -gt 0 ]; then
  "$bin/op2gs-report" "${report_scenes[@]}" --metrics metrics.json --no-viewer --out "$out/report" \
    --title "op2gs: real-capture study (oracle mode, LERF-Mask protocol)" > /dev/null
  echo "report: $out/report/report.html"
fi
