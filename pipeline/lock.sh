#!/usr/bin/env bash
# One make at a time per work folder: records the calling make's process ID
# and start time in WORK/.op2gs.make unless another live make holds it, in
# which case it prints why (pipeline/Makefile stops with that message). A make that ended,
# however it ended, holds nothing: its process is gone.
#
# Usage: lock.sh WORK_ROOT MAKE_PID
set -uo pipefail
work="$1" pid="$2"
mkdir -p "$work"
exec 9> "$work/.op2gs.make.guard"
flock 9
# A process is known by its ID and its start time (field 22 of
# /proc/PID/stat), as IDs are reused: a dead make's ID may now be another's.
# A zombie (state Z: killed, its parent gone, init not reaping it) has ended.
started() { sed 's/.*) //' "/proc/$1/stat" 2> /dev/null | awk '$1 != "Z" && $1 != "X" {print $20}'; }
# The record is missing in a new work folder. (A failed "< file" is reported
# before a "2> /dev/null" after it takes effect, so test for the file.)
holder="" holder_start=""
if [ -f "$work/.op2gs.make" ]; then read -r holder holder_start < "$work/.op2gs.make"; fi
if [ -n "$holder" ] && [ "$holder" != "$pid" ] && [ -n "$(started "$holder")" ] &&
   [ "$(started "$holder")" = "$holder_start" ] &&
   grep -qa make "/proc/$holder/cmdline" 2> /dev/null; then
  echo "$work: another make (process $holder) is running in this work folder; wait for it to finish"
  exit 0
fi
echo "$pid $(started "$pid")" > "$work/.op2gs.make"
