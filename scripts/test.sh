#!/usr/bin/env bash
# Sets up (Debian packages + Release build) and runs the whole test suite.
# Beside them, fuzzes every parser of user files briefly (scripts/fuzz.sh,
# OP2GS_FUZZ_SECONDS = 5 each; docs/reliability.md). Exits non-zero when any
# test fails or any harness crashes.
# A test that cannot run here (a tool missing) is skipped and listed by name
# at the end; with CI=true (.ci/run) it fails instead (tests/pipeline/test_lib.sh).
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
ctest_log=$(mktemp)
ctest --test-dir "$root/build" --output-on-failure --parallel "$(nproc)" 2>&1 | tee "$ctest_log" ||
  status=1
if [ "$fuzz_seconds" -gt 0 ]; then
  wait $! || status=1
  cat "$fuzz_log"
fi
# ctest counts a skipped test as passed: name each one.
skipped=$(grep -E '\*\*\*(Skipped|Not Run)' "$ctest_log" | sed -E 's/^ *[0-9]+\/[0-9]+ Test +#[0-9]+: ([^ ]+).*/\1/' || true)
if [ -n "$skipped" ]; then
  echo "skipped (could not run here; CI=true makes this a failure):"
  echo "$skipped" | sed 's/^/  /'
fi
rm -f "$fuzz_log" "$ctest_log"
exit "$status"
