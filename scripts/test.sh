#!/usr/bin/env bash
# Sets up (Debian packages + Release build) and runs the whole test suite.
# Beside them, fuzzes every parser of user files briefly (scripts/fuzz.sh,
# OP2GS_FUZZ_SECONDS = 5 each; docs/reliability.md). Exits non-zero when any
# test fails or any harness crashes.
# Usage: scripts/test.sh [setup.sh options]   (OP2GS_FUZZ_SECONDS=0 skips fuzzing)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/setup.sh" --tests "$@"
# The fuzzing runs beside the tests at the lowest priority: it takes the CPU
# time the tests leave idle (waits, processes starting, files).
fuzz_seconds="${OP2GS_FUZZ_SECONDS:-5}"
fuzz_log=$(mktemp)
if [ "$fuzz_seconds" -gt 0 ]; then
  nice -n 19 "$root/scripts/fuzz.sh" "$fuzz_seconds" "$root/build-fuzz" > "$fuzz_log" 2>&1 &
fi
status=0
ctest --test-dir "$root/build" --output-on-failure --parallel "$(nproc)" || status=1
if [ "$fuzz_seconds" -gt 0 ]; then
  wait $! || status=1
  cat "$fuzz_log"
fi
rm -f "$fuzz_log"
exit "$status"
