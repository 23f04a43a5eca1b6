#!/usr/bin/env bash
# Sets up (Debian packages + Release build) and runs the whole test suite.
# Then fuzzes every parser of user files briefly (scripts/fuzz.sh, OP2GS_FUZZ_SECONDS = 10
# each; docs/reliability.md). Exits non-zero when any test fails or any
# harness crashes.
# Usage: scripts/test.sh [setup.sh options]   (OP2GS_FUZZ_SECONDS=0 skips fuzzing)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/setup.sh" --tests "$@"
ctest --test-dir "$root/build" --output-on-failure --parallel "$(nproc)"
fuzz_seconds="${OP2GS_FUZZ_SECONDS:-10}"
if [ "$fuzz_seconds" -gt 0 ]; then
  "$root/scripts/fuzz.sh" "$fuzz_seconds" "$root/build-fuzz"
fi
