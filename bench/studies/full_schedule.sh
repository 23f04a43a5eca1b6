#!/usr/bin/env bash
# The whole training schedule on a LERF-Mask-sized scene: what a user waits
# for. The scene is synthetic (op2gs-synth, 300 views at 986x728 like
# LERF-Mask's figurines, generated once and cached in DIR/scene).
#
#   bench/studies/full_schedule.sh full    BUILD DIR
#       The paper's schedule once: stage one to 20,000 (checkpoints kept at
#       2k, 5k, 10k, 15k, 20k), voting, stage two to 30,000 (kept at 25k).
#       Hours on 2 cores; writes DIR/full/summary.txt (times, peak memory,
#       test PSNR, Gaussians) and the kept checkpoints the other modes use.
#       Run it again after an interruption and it continues: finished stages
#       are skipped, the others resume from their latest checkpoint (every
#       1,000 iterations). RESTART=1 starts over.
#       Stage two is op2gs-learn --recipe paper, the paper's object loss.
#       RECIPE=fast runs the fast recipe instead (op2gs-train --recipe fast,
#       op2gs-learn --recipe paper --sparse-adam --half-views-from 1) into
#       DIR/full-fast, beside the paper's. RECIPE=dash likewise runs the
#       dash recipe (an experiment) into DIR/full-dash, and RECIPE=fast-hold
#       the fast one with dash's hold of the position learning rate.
#       Then renders the test views' masks and scores them (oracle mode of the
#       LERF-Mask protocol, DIR/full/masks.json).
#   bench/studies/full_schedule.sh variant BUILD DIR NAME [op2gs-learn options]
#       Stage two again from the full run's stage one (its 20,000 checkpoint
#       and its vote) with other op2gs-learn options, e.g.
#       "variant build DIR robust --recipe robust", into DIR/variant-NAME,
#       resumable like full; its masks scored as full's (masks.json). UNTIL
#       (30000) ends it earlier, e.g. 23000 for a quicker comparison.
#   bench/studies/full_schedule.sh summary DIR   (RECIPE=fast: DIR/full-fast)
#       What the full run has done so far (it may be unfinished): time per
#       stage summed over its sessions, Gaussians, peak memory, test PSNR.
#   bench/studies/full_schedule.sh sampled BUILD DIR [THREADS]
#       Resumes from each kept checkpoint (and from the SfM points), times
#       SAMPLE iterations (300), and integrates the rate over the schedule:
#       the estimated full time. Missing checkpoints are left out.
#   bench/studies/full_schedule.sh paired  OLD_BUILD NEW_BUILD DIR [THREADS]
#       The same with two builds alternated at every checkpoint (old, new,
#       new, old), so the VM's speed drift cancels in the ratio.
#   bench/studies/full_schedule.sh options BUILD DIR "OPTIONS_A" "OPTIONS_B"
#       The same with one build and two sets of training options alternated
#       (A, B, B, A), given to both stages, e.g. "" "--sparse-adam
#       --half-views-from 1": what the fast recipe's options save at the
#       paper's model sizes (the output calls A "old" and B "new").
#   bench/studies/full_schedule.sh runs BUILD DIR RUN_A "OPTIONS_A" RUN_B "OPTIONS_B"
#       The same, each arm resumed from its own run's kept checkpoints
#       (DIR/RUN_A, DIR/RUN_B, e.g. full and a stage one of other options),
#       with its own options: what another recipe's models cost an
#       iteration, each at its own size. Stage two's points need each run's
#       vote and stage-two checkpoints.
#   bench/studies/full_schedule.sh threads BUILD DIR
#       Thread scaling: 1 and 2 threads alternated at every checkpoint.
#   bench/studies/full_schedule.sh profile BUILD DIR ITERATION
#       perf over SAMPLE iterations resumed at ITERATION, grouped by phase
#       (bench/studies/full_schedule_phases.py).
#
# Environment: SAMPLE (iterations timed per checkpoint, 300), POINTS (the
# iterations sampled, "0 2000 5000 10000 15000 20000 25000"), WARMUP
# (iterations run untimed before the SAMPLE, 0: a resumed run decodes every
# view once in its first epoch, which an uninterrupted run with its view
# cache warm does not; one epoch, the training views' count, times the warm
# cache), VIEWS, WIDTH, HEIGHT (the scene, 300 986 728).
set -euo pipefail
mode="${1:?usage: bench/studies/full_schedule.sh full|variant|summary|sampled|paired|options|runs|threads|profile ...}"
shift
here="$(cd "$(dirname "$0")" && pwd)"
# shellcheck source=bench/timing.sh
source "$here/../timing.sh"  # stage_one_hold
sample="${SAMPLE:-300}"
warmup="${WARMUP:-0}"
stage_one_points=(2000 5000 10000 15000)
read -r -a points <<< "${POINTS:-0 ${stage_one_points[*]} 20000 25000}"

# A timed run, its output in its folder's run.log; a failing run prints the
# log's tail and fails (the caller then fails the mode).
run() {
  local tmp="$1"
  shift
  if ! "$@" > "$tmp/run.log" 2>&1; then
    echo "bench/studies/full_schedule.sh: failed: $*" >&2
    tail -3 "$tmp/run.log" >&2
    return 1
  fi
}

make_scene() {  # DIR BUILD
  [ -f "$1/scene/.complete" ] && return
  rm -rf "$1/scene"
  "$2/stages/op2gs-synth" "$1/scene" --views "${VIEWS:-300}" --width "${WIDTH:-986}" \
    --height "${HEIGHT:-728}" > /dev/null
  touch "$1/scene/.complete"
}

# Renders the test views' masks of a finished stage two and scores them
# (oracle mode, LERF-Mask protocol): WORK/render/, WORK/masks.json.
score_masks() {  # BUILD DIR WORK
  "$1/stages/op2gs-render" "$2/scene" "$3" > "$3/render.log" 2>&1 ||
    { tail -3 "$3/render.log" >&2; return 1; }
  "$1/stages/op2gs-eval" "$2/scene" --protocol lerf --pred dual-opacity="$3/render/masks" \
    --pred baseline="$3/render/baseline_labels" --out "$3/masks.json" > "$3/eval.log" 2>&1 ||
    { tail -3 "$3/eval.log" >&2; return 1; }
  python3 - "$3/masks.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))["results"]
for name in ("dual-opacity", "baseline"):
    m = r[name]
    print(f'{name}: mIoU {100 * m["miou"]:.1f}, mBIoU {100 * m["mbiou"]:.1f}; ' + "; ".join(
        f'{q["query"]} {100 * q["miou"]:.1f} / {100 * q["mbiou"]:.1f}' for q in m["queries"]))
PY
}

# Runs a stage and appends one line to $segments: its wall time and peak
# memory (a stage that was interrupted and resumed has several). Shows its
# log without the progress bar.
timed() {  # NAME COMMAND...
  local name="$1"
  shift
  /usr/bin/time -a -o "$segments" -f "$name: %e s, peak %M KiB" "$@" 2>&1 |
    tr '\r' '\n' | grep -v '^\[[#-]'
}

# The full run's training recipe (RECIPE: paper, fast, dash or fast-hold) and its folder.
# All keep the paper's object loss in stage two (op2gs-learn --recipe
# paper), which the figures of docs/benchmarks.md were measured with; other
# object losses run as variants from the same stage one.
recipe="${RECIPE:-paper}"
train_recipe=(--recipe "$recipe")
learn_recipe=(--recipe paper)
case "$recipe" in
  paper) ;;
  fast) learn_recipe+=(--sparse-adam --half-views-from 1) ;;
  dash) learn_recipe+=(--sparse-adam --half-views-from 1) ;;
  # The fast recipe with dash's hold rule (until the views are half size:
  # 3,750 on the fast recipe's schedule), to tell the hold's effect apart.
  fast-hold)
    train_recipe=(--recipe fast --position-lr-hold-until 3750)
    learn_recipe+=(--sparse-adam --half-views-from 1)
    ;;
  *) echo "bench/studies/full_schedule.sh: RECIPE=$recipe: paper, fast, dash or fast-hold" >&2; exit 2 ;;
esac
full_run_folder() { if [ "$recipe" = paper ]; then echo full; else echo "full-$recipe"; fi; }

# Seconds per iteration over a run's log after iteration FROM + 1 (whose
# time carries the loading, or the warm-up).
rate() {  # LOG FROM
  python3 - "$1" "$2" <<'PY'
import json, sys
r = [json.loads(l) for l in open(sys.argv[1]) if '"elapsed_s"' in l]
r = [x for x in r if x["iteration"] > int(sys.argv[2])]
print((r[-1]["elapsed_s"] - r[0]["elapsed_s"]) / (r[-1]["iteration"] - r[0]["iteration"]))
PY
}

# Runs STAGE in TMP resumed from the full run's checkpoint of iteration k
# (SUBDIR: where the stage keeps its checkpoints, "" or "learn/"); fails
# when that checkpoint was not kept. Uses time_from's variables.
resume_from() {  # TMP FULL SUBDIR STAGE
  local kept="$2/$3checkpoints/iteration_$k.ckpt"
  [ -f "$kept" ] || return 1
  mkdir -p "$1/$3checkpoints"
  ln -s "$kept" "$1/$3checkpoints/latest.ckpt"
  run "$1" "$bin/$4" "$dir/scene" "$1" --resume --iterations "$stop" \
    --checkpoint-every 1000000 --threads "$threads" $no_test "${extra[@]}" || exit 1
}

# Times SAMPLE iterations from iteration K (after WARMUP untimed ones) with
# BUILD, the training options in $options (none if unset) and the kept
# checkpoints of DIR/$run (DIR/full if unset); prints seconds per
# iteration, or nothing when K's checkpoint is missing.
time_from() {  # BUILD DIR K THREADS
  local bin="$1/stages" dir="$2" k="$3" threads="$4" tmp log extra
  read -r -a extra <<< "${options:-}"
  local stop=$((k + warmup + sample))
  local full="$dir/${run:-full}"
  tmp="$(mktemp -d "$dir/sample.XXXXXX")"
  # Skip the test views at the end (builds older than the flag score them,
  # outside the timed iterations).
  local no_test=""
  "$bin/op2gs-train" --help | grep -q -- --no-final-test && no_test=--no-final-test
  if [ "$k" -eq 0 ]; then
    run "$tmp" "$bin/op2gs-train" "$dir/scene" "$tmp" --iterations "$stop" --threads "$threads" \
      $no_test "${extra[@]}" || exit 1
    log="$tmp/train_log.jsonl"
  elif [ "$k" -lt 20000 ]; then
    resume_from "$tmp" "$full" "" op2gs-train || { rm -rf "$tmp"; return; }
    log="$tmp/train_log.jsonl"
  elif [ "$k" -eq 20000 ]; then
    [ -f "$full/vote/point_cloud.ply" ] || { rm -rf "$tmp"; return; }
    run "$tmp" "$bin/op2gs-learn" "$dir/scene" "$tmp" --checkpoint "$full/checkpoints/iteration_$k.ckpt" \
      --labels "$full/vote/point_cloud.ply" --iterations "$stop" \
      --checkpoint-every 1000000 --threads "$threads" $no_test "${extra[@]}" || exit 1
    log="$tmp/learn/train_log.jsonl"
  else
    resume_from "$tmp" "$full" learn/ op2gs-learn || { rm -rf "$tmp"; return; }
    log="$tmp/learn/train_log.jsonl"
  fi
  if [ ! -f "$log" ]; then
    echo "bench/studies/full_schedule.sh: the run from iteration $k with $1 failed:" >&2
    tail -3 "$tmp/run.log" >&2
    rm -rf "$tmp"
    return 1
  fi
  rate "$log" $((k + warmup))
  rm -rf "$tmp"
}

# Times each sampled point four times, arm A, B, B, A, so that the VM's
# drift hits both alike, and prints "K a1 a2 b1 b2" lines. An arm is a
# build, a thread count and training options, and the run whose checkpoints
# it resumes ($run_a, $run_b: full if unset).
alternate() {  # DIR A_BUILD A_THREADS A_OPTIONS B_BUILD B_THREADS B_OPTIONS
  local dir="$1" k a1 a2 b1 b2 ra="${run_a:-full}" rb="${run_b:-full}"
  for k in "${points[@]}"; do
    a1="$(run="$ra" options="$4" time_from "$2" "$dir" "$k" "$3")"
    [ -n "$a1" ] || continue
    b1="$(run="$rb" options="$7" time_from "$5" "$dir" "$k" "$6")"
    if [ -z "$b1" ]; then
      echo "bench/studies/full_schedule.sh: $dir/$rb has no checkpoint at $k: the point is left out" >&2
      continue
    fi
    b2="$(run="$rb" options="$7" time_from "$5" "$dir" "$k" "$6")"
    a2="$(run="$ra" options="$4" time_from "$2" "$dir" "$k" "$3")"
    echo "$k $a1 $a2 $b1 $b2"
  done
}

# Reads "K seconds-per-iteration" lines; prints the schedule's estimated time.
# (The modes copy the raw lines to stderr with `tee >(cat >&2)`: `tee
# /dev/stderr` would reopen a log that stderr is redirected to, truncating it.)
integrate() {
  python3 "$here/full_schedule_integrate.py"
}

case "$mode" in
  full)
    build="$1" dir="$2"
    mkdir -p "$dir"
    make_scene "$dir" "$build"
    full="$dir/$(full_run_folder)"
    [ "${RESTART:-0}" = 1 ] && rm -rf "$full"
    mkdir -p "$full"
    bin="$build/stages"
    segments="$full/segments.log"
    echo "session: $(date -u +%FT%TZ) commit $(git -C "$here" rev-parse --short HEAD)" >> "$segments"
    if [ ! -f "$full/metrics.json" ]; then
      resume=()
      [ -f "$full/checkpoints/latest.ckpt" ] && resume=(--resume)
      timed "stage one" "$bin/op2gs-train" "$dir/scene" "$full" "${resume[@]}" \
        --keep-checkpoint-at "${stage_one_points[@]}" 20000 --iterations 20000 \
        "${train_recipe[@]}"
    fi
    [ -f "$full/vote/point_cloud.ply" ] || timed "voting" "$bin/op2gs-vote" "$dir/scene" "$full"
    if [ ! -f "$full/learn/metrics.json" ]; then
      resume=()
      [ -f "$full/learn/checkpoints/latest.ckpt" ] && resume=(--resume)
      timed "stage two" "$bin/op2gs-learn" "$dir/scene" "$full" "${resume[@]}" \
        --keep-checkpoint-at 25000 --iterations 30000 "${learn_recipe[@]}" \
        --position-lr-hold-until "$(stage_one_hold "$full")"
    fi
    [ -f "$full/masks.json" ] || score_masks "$build" "$dir" "$full" > "$full/masks.txt"
    python3 "$here/full_schedule_summary.py" "$full" | tee "$full/summary.txt"
    cat "$full/masks.txt"
    ;;
  variant)
    build="$1" dir="$2" name="$3"
    shift 3
    full="$dir/full" work="$dir/variant-$name"
    for f in checkpoints/iteration_20000.ckpt vote/point_cloud.ply; do
      [ -f "$full/$f" ] || { echo "bench/studies/full_schedule.sh: $full/$f: missing (run full first)" >&2; exit 1; }
    done
    [ "${RESTART:-0}" = 1 ] && rm -rf "$work"
    mkdir -p "$work"
    segments="$work/segments.log"
    echo "session: $(date -u +%FT%TZ) commit $(git -C "$here" rev-parse --short HEAD): $*" >> "$segments"
    if [ ! -f "$work/learn/metrics.json" ]; then
      resume=()
      [ -f "$work/learn/checkpoints/latest.ckpt" ] && resume=(--resume)
      timed "stage two" "$build/stages/op2gs-learn" "$dir/scene" "$work" "${resume[@]}" \
        --checkpoint "$full/checkpoints/iteration_20000.ckpt" --labels "$full/vote/point_cloud.ply" \
        --iterations "${UNTIL:-30000}" "$@"
      [ -f "$work/learn/metrics.json" ] || { echo "bench/studies/full_schedule.sh: stage two failed" >&2; exit 1; }
    fi
    [ -f "$work/masks.json" ] || score_masks "$build" "$dir" "$work" > "$work/masks.txt"
    cat "$work/masks.txt"
    ;;
  summary)
    python3 "$here/full_schedule_summary.py" "$1/$(full_run_folder)"
    ;;
  sampled)
    build="$1" dir="$2" threads="${3:-0}"
    make_scene "$dir" "$build"
    for k in "${points[@]}"; do
      r="$(time_from "$build" "$dir" "$k" "$threads")"
      [ -n "$r" ] && echo "$k $r"
    done | tee >(cat >&2) | integrate
    ;;
  paired)
    old="$1" new="$2" dir="$3" threads="${4:-0}"
    make_scene "$dir" "$new"
    alternate "$dir" "$old" "$threads" "" "$new" "$threads" "" |
      tee >(cat >&2) | python3 "$here/full_schedule_integrate.py" --paired
    ;;
  options)
    build="$1" dir="$2" a="$3" b="$4"
    make_scene "$dir" "$build"
    alternate "$dir" "$build" 0 "$a" "$build" 0 "$b" |
      tee >(cat >&2) | python3 "$here/full_schedule_integrate.py" --paired
    ;;
  runs)
    build="$1" dir="$2"
    for r in "$3" "$5"; do
      [ -d "$dir/$r/checkpoints" ] || { echo "bench/studies/full_schedule.sh: $dir/$r: no checkpoints" >&2; exit 1; }
    done
    run_a="$3" run_b="$5" alternate "$dir" "$build" 0 "$4" "$build" 0 "$6" |
      tee >(cat >&2) | python3 "$here/full_schedule_integrate.py" --paired
    ;;
  threads)
    build="$1" dir="$2"
    make_scene "$dir" "$build"
    alternate "$dir" "$build" 1 "" "$build" 2 "" |
      tee >(cat >&2) | python3 "$here/full_schedule_integrate.py" --threads
    ;;
  profile)
    build="$1" dir="$2" k="$3"
    make_scene "$dir" "$build"
    data="$dir/perf.$k.data"
    # perf follows the stage's threads; the phases are named after the
    # functions that do their work (bench/studies/full_schedule_phases.py).
    perf record -F 499 -o "$data" -- "$0" sampled-one "$build" "$dir" "$k" > /dev/null 2>&1
    perf report -i "$data" --no-children --sort dso,sym --stdio 2> /dev/null |
      python3 "$here/full_schedule_phases.py"
    ;;
  sampled-one)  # used by profile
    time_from "$1" "$2" "$3" 0
    ;;
  *)
    echo "bench/studies/full_schedule.sh: unknown mode '$mode' (full, variant, summary, sampled, paired, options, runs, threads or profile)" >&2
    exit 2
    ;;
esac
