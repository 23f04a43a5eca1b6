#!/usr/bin/env bash
# Runs one stage of one scene for pipeline/Makefile: prints what runs, keeps
# the whole output in the stage's log (and shows it), and on failure says in
# one line which scene and stage failed, why, and where the log is.
#
# Usage: run_stage.sh SCENE STAGE LOG LAUNCH COMMAND
set -uo pipefail
scene="$1" stage="$2" log="$3" launch="$4" command="$5"
mkdir -p "$(dirname "$log")"
echo "== $scene: $stage" >&2
start=$(date +%s)
{
  echo "# $(date -Is) $scene $stage"
  echo "# $command"
} > "$log"
# What libraries print themselves goes into the log, not the terminal
# (stages/common.h, StageOutput).
export OP2GS_LIBRARY_LOG="$log"
if [ -n "$launch" ]; then
  $launch bash -c "$command" 2>&1 | tee -a "$log"
else
  bash -c "$command" 2>&1 | tee -a "$log"
fi
status=${PIPESTATUS[0]}
if [ "$status" -ne 0 ]; then
  # Every stage ends with its one-line error; drop the time stamp.
  reason=$(grep -v '^#' "$log" | sed '/^\s*$/d' | tail -1 | sed 's/^\[[0-9:]*\] //')
  echo "op2gs: $scene: stage $stage failed (exit $status): ${reason:-see the log}; log: $log" >&2
  exit "$status"
fi
echo "== $scene: $stage done in $(( $(date +%s) - start )) s" >&2
