#!/usr/bin/env bash
# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer:
# builds everything with them (OP2GS_SANITIZE; BUILD_DIR, default
# build-asan/) and runs every test, the stage binaries the pipeline tests
# start included. Each sanitizer report goes to a file of its own; the run
# fails when a test fails or when there is any report (they are printed).
# Every test passes under it, the pipeline and fault tests included, in about
# 45 minutes of tests on 2 cores after a 40-minute build (docs/reliability.md).
# Usage: scripts/sanitize.sh [BUILD_DIR]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$root/build-asan}"
reports=$(mktemp -d)
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DOP2GS_SANITIZE=ON \
  -DOP2GS_BUILD_BENCH=OFF > "$reports/configure.log" || { cat "$reports/configure.log"; exit 1; }
cmake --build "$build" --parallel "$(nproc)"
# Distinct exit codes, so that no test mistakes a sanitizer's exit for a
# stage refusing its input.
export ASAN_OPTIONS="log_path=$reports/asan:exitcode=86:detect_leaks=1:abort_on_error=0"
export UBSAN_OPTIONS="log_path=$reports/ubsan:halt_on_error=1:exitcode=87:print_stacktrace=1"
export LSAN_OPTIONS="suppressions=$root/tests/fuzz/lsan.supp:print_suppressions=0"
status=0
ctest --test-dir "$build" --output-on-failure --parallel "$(nproc)" || status=1
found=$(find "$reports" -name 'asan.*' -o -name 'ubsan.*' | sort)
if [ -n "$found" ]; then
  echo "sanitizer reports ($(wc -l <<< "$found")):"
  for f in $found; do
    echo "== $f"
    head -30 "$f"
  done
  status=1
fi
[ "$status" -eq 0 ] && echo "sanitizers: no report, every test passed"
exit "$status"
