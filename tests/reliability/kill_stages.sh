#!/usr/bin/env bash
# Every stage of a dataset run killed outright (kill -9 of make and everything
# it started), KILLS times per stage at seeded random moments inside it,
# with the stage run for the first time and run again; the next make of
# that stage finishes it, and the work folder is then byte-identical to an
# uninterrupted run's. The stages after it are not run again for each kill:
# their inputs are then the uninterrupted run's, byte for byte, so they would
# only repeat that run (each stage's start-up, about half a second of loading
# libraries, is most of this test's time). Once, a run killed in its first
# stage is finished by a plain make through every stage after it. Left out
# of the comparison: what records wall-clock time (the training logs'
# elapsed_s, render/timing.json, vote/summary.json) and the logs.
# Usage: kill_stages.sh BIN_DIR [KILLS] [SEED]
source "$(dirname "${BASH_SOURCE[0]}")/../pipeline/test_lib.sh" "$1"
kills="${2:-2}" seed="${3:-1}"
tiny_lerf_run "$tmp/work"
outputs() { work_outputs "$tmp/work"; }
now_ms() { local t=${EPOCHREALTIME/./}; echo $((t / 1000)); }
# Each line of the input with the moment it arrived (ms) in front.
stamp_lines() { while IFS= read -r line; do echo "$(now_ms) $line"; done; }

mk "${run[@]}" 2>&1 | stamp_lines > "$tmp/reference.log" ||
  { tail -5 "$tmp/reference.log"; fail "the reference run failed"; }
reference=$(outputs)
[ "$(wc -l <<< "$reference")" -gt 20 ] || fail "the reference run left too few outputs"

# The stages in the order they ran ("scene: stage"), and how long each took.
mapfile -t stages < <(sed -n 's/^[0-9]* == \(.*: [a-z-]*\)$/\1/p' "$tmp/reference.log")
[ "${#stages[@]}" -ge 8 ] || { cat "$tmp/reference.log"; fail "the reference run ran only ${#stages[@]} stages"; }
duration_ms() {
  local start end
  start=$(grep -m1 " == $1\$" "$tmp/reference.log" | cut -d' ' -f1)
  end=$(grep -m1 " == $1 done in" "$tmp/reference.log" | cut -d' ' -f1)
  echo $((end - start > 1 ? end - start : 1))
}

# The make target that runs stage "scene: stage" alone.
target_of() {
  local scene=${1%%:*} stage=${1#*: }
  if [ "$stage" = dataset-report ]; then echo report; else echo "$scene.$stage"; fi
}

# Starts make TARGET, waits until STAGE has begun, kills everything AT_MS later.
run_and_kill() {
  local stage="$1" target="$2" at_ms="$3" leader waited=0
  setsid make --no-print-directory -f "$root/pipeline/Makefile" BIN="$bin" "${run[@]}" "$target" \
    > "$tmp/killed.log" 2>&1 &
  leader=$!
  until grep -qs "^== $stage\$" "$tmp/killed.log"; do
    kill -0 "$leader" 2> /dev/null || { tail -5 "$tmp/killed.log"; fail "make ended before $stage began"; }
    sleep 0.01
    ((++waited < 6000)) || { kill -9 -- "-$leader"; fail "$stage never started"; }
  done
  sleep "$(printf '%d.%03d' $((at_ms / 1000)) $((at_ms % 1000)))"
  kill -9 -- "-$leader" 2> /dev/null || true
  wait "$leader" 2> /dev/null || true
  # SIGKILL takes effect as each process next runs; wait until none of the
  # run's processes is left but zombies (where init does not reap them).
  while ps -o stat= -s "$leader" 2> /dev/null | grep -qv '^Z'; do sleep 0.01; done
}

# The finished run with stage $1 to do again (its stamp removed), and with
# $2 = fresh its outputs too, as if it had never run (else as after a change
# of its options). With $3 = through, every stage after it as well.
to_do() {
  rm -rf "$tmp/work"
  cp -a "$tmp/finished" "$tmp/work"
  local s later=0 scene stage
  for s in "${stages[@]}"; do
    [ "$s" = "$1" ] && later=1
    ((later)) || continue
    scene=${s%%:*} stage=${s#*: }
    if [ "$stage" = dataset-report ]; then
      rm "$tmp/work/stamps/dataset-report.done"
      [ "$2" != fresh ] || rm -rf "$tmp/work/report"
    else
      rm "$tmp/work/$scene/stamps/$stage.done"
      if [ "$2" = fresh ]; then
        case "$stage" in
          train) (cd "$tmp/work/$scene" && rm -rf checkpoints point_cloud test train_log.jsonl \
                    training_curve.png metrics.json) ;;
          *) rm -rf "${tmp:?}/work/$scene/$stage" ;;
        esac
      fi
    fi
    [ "${3:-}" = through ] || break
  done
}
cp -a "$tmp/work" "$tmp/finished"

# The next make of TARGET after a kill (WHAT says which) finishes it, and
# the work folder is then the uninterrupted run's.
rerun_and_compare() {
  local what="$1" target="$2"
  mk "${run[@]}" ${target:+"$target"} > "$tmp/after.log" 2>&1 ||
    { tail -5 "$tmp/after.log"; fail "$what: the run after it failed"; }
  if [ "$(outputs)" != "$reference" ]; then
    diff <(echo "$reference") <(outputs) | head -5 || true
    fail "$what: outputs differ from the uninterrupted run"
  fi
  echo "$what: outputs identical after the rerun"
}

# Odd kills find the stage never run before, even ones find its outputs of
# an earlier run (so it replaces them). Either way the stages before it are
# done and those after it are left as they are, so each kill costs only
# that stage.
RANDOM=$seed
for stage in "${stages[@]}"; do
  took=$(duration_ms "$stage")
  target=$(target_of "$stage")
  for ((k = 1; k <= kills; k++)); do
    if ((k % 2)); then to_do "$stage" fresh; else to_do "$stage" again; fi
    at_ms=$((RANDOM % took))
    run_and_kill "$stage" "$target" "$at_ms"
    rerun_and_compare "killed ${at_ms} ms into $stage (of $took ms)" "$target"
  done
done
# A run killed in its first stage, with every stage to do: a plain make
# finishes the whole run.
first="${stages[0]}"
to_do "$first" fresh through
at_ms=$((RANDOM % $(duration_ms "$first")))
run_and_kill "$first" all "$at_ms"
rerun_and_compare "killed ${at_ms} ms into $first, every stage after it to do" ""
# The one moment random kills seldom hit: after the report's swap (report.html
# already in place), before its staging folder, holding the replaced files,
# was removed. The stamp is not written then, so the next make runs the
# report again, which removes the dead run's staging folder.
for s in "${stages[@]}"; do [[ "$s" != *": dataset-report" ]] || report_stage="$s"; done
to_do "$report_stage" again
mkdir -p "$tmp/work/report/.staging-999999999-1"
cp "$tmp/work/report/report.md" "$tmp/work/report/.staging-999999999-1/"
rerun_and_compare "killed between the report's swap and its clean-up" ""
echo "PASS"
