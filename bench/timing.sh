# shellcheck shell=bash disable=SC2154
# Shared by the bench scripts that time op2gs's training steps
# (opensplat_ab.sh, thread_scaling.sh, stage_two_cost.sh) and run its
# stages (studies/full_schedule.sh, studies/capture_study.sh): sourced, not
# run. A script that calls step sets `logs`, the folder its steps' logs go to.

# Stops the script with a one-line message.
fail() {
  echo "$(basename "$0" .sh): $*" >&2
  exit 1
}

# Runs a step with its output in $logs/<label>.log; on failure prints its
# tail and stops.
step() {
  local label="$1"
  shift
  if ! "$@" > "$logs/$label.log" 2>&1; then
    tail -20 "$logs/$label.log" >&2
    fail "$label failed (log: $logs/$label.log)"
  fi
}

# Runs op2gs-train as step LABEL in a fresh folder WORK, resumed from
# CHECKPOINT; COMMAND... is the binary and its arguments, WORK left out.
# --resume reads WORK/checkpoints/latest.ckpt, here a link to CHECKPOINT:
# the run's own checkpoints replace the link by renaming, never write
# through it.
resume_in_fresh_folder() {  # LABEL CHECKPOINT WORK COMMAND...
  local label="$1" checkpoint="$2" work="$3"
  shift 3
  rm -rf "$work"
  mkdir -p "$work/checkpoints"
  ln -s "$checkpoint" "$work/checkpoints/latest.ckpt"
  step "$label" "$@" "$work" --resume
}

# The position learning rate's hold a stage-one run trained with (its
# metrics.json; 0 when it had none), for stage two to go on with.
stage_one_hold() {  # WORK
  python3 -c 'import json, sys; print(json.load(open(sys.argv[1])).get("position_lr_hold_until", 0))' \
    "$1/metrics.json"
}

# The median of the numbers on stdin, one a line; fails on none.
median() { sort -g | awk '{ a[NR] = $1 } END { if (NR == 0) exit 1; print a[int((NR + 1) / 2)] }'; }

# Seconds per iteration of an op2gs run: the median step of its train log,
# the first step (FIRST) left out. Fails unless every step is there.
op2gs_seconds() {  # LOG FIRST LAST
  local log="$1" first="$2" last="$3"
  local n
  n=$(awk '/"iteration"/ { n++ } END { print n + 0 }' "$log")
  [ "$n" -ge $((last - first + 1)) ] || fail "$log: $n iterations logged, expected $((last - first + 1))"
  grep '"elapsed_s"' "$log" | sed -E 's/.*"elapsed_s":([0-9.e+-]+).*"iteration":([0-9]+).*/\2 \1/' |
    awk -v first="$first" '$1 > first { if (prev != "") print $2 - prev; prev = $2 } $1 == first { prev = $2 }' |
    median
}

# The steps of an op2gs run made with --alternate-threads, the first step
# (FIRST) left out: one line "THREADS SECONDS" a step. Fails unless every
# step is there with its thread count.
op2gs_steps_by_threads() {  # LOG FIRST LAST
  local log="$1" first="$2" last="$3"
  local n
  n=$(awk '/"threads"/ { n++ } END { print n + 0 }' "$log")
  [ "$n" -ge $((last - first + 1)) ] || fail "$log: $n iterations logged with their threads, expected $((last - first + 1))"
  grep '"threads"' "$log" |
    sed -E 's/.*"elapsed_s":([0-9.e+-]+).*"iteration":([0-9]+).*"threads":([0-9]+).*/\2 \1 \3/' |
    awk -v first="$first" '$1 > first { print $3, $2 - prev } { prev = $2 }'
}

# The Gaussians of an op2gs run's last logged step (a test line has none).
op2gs_gaussians() { grep '"gaussians"' "$1" | tail -1 | sed -E 's/.*"gaussians":([0-9]+).*/\1/'; }
