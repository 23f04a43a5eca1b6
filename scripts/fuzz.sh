#!/usr/bin/env bash
# Builds the fuzz harnesses of the parsers (clang, with AddressSanitizer and
# UndefinedBehaviorSanitizer; tests/fuzz/) and runs each for SECONDS, one per
# core at a time, on a copy of its seed corpus (tests/fuzz/corpus/<parser>/).
# Prints the executions and the crashes of each; exits 1 if any harness
# crashed or ran nothing, leaving the inputs that crashed in OUT (default: a
# temporary folder, named in the output).
# Built at -O1 (as OSS-Fuzz does; assertions on): it compiles in half the
# time of -O3, which lets CI (scripts/test.sh) fuzz every parser briefly.
# Usage: scripts/fuzz.sh [SECONDS] [BUILD_DIR] [OUT]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds="${1:-30}" build="${2:-$root/build-fuzz}" out="${3:-$(mktemp -d)}"
mkdir -p "$out"
command -v clang++ > /dev/null || { echo "fuzz: needs clang (apt-get install clang)" >&2; exit 1; }
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -DOP2GS_FUZZ=ON -DOP2GS_BUILD_TESTS=OFF \
  -DOP2GS_BUILD_BENCH=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 \
  > "$out/configure.log" ||
  { cat "$out/configure.log"; exit 1; }
cmake --build "$build" -j"$(nproc)" --target fuzzers > "$out/build.log" 2>&1 ||
  { tail -30 "$out/build.log"; exit 1; }
# The harnesses hand each input to the parsers as a file: in memory it is 4x faster.
[ -d /dev/shm ] && [ -w /dev/shm ] && export TMPDIR="${TMPDIR:-/dev/shm}"
export LSAN_OPTIONS="suppressions=$root/tests/fuzz/lsan.supp:print_suppressions=0"
total=0 crashed=0 idle=0
# Every harness tests/fuzz/CMakeLists.txt declares must have been built.
expected=$(grep -c '^op2gs_fuzzer(' "$root/tests/fuzz/CMakeLists.txt")
built=$(find "$build/tests/fuzz" -maxdepth 1 -name 'fuzz_*' -type f -executable 2> /dev/null | wc -l)
if [ "$built" -ne "$expected" ]; then
  echo "fuzz: $built harnesses built, tests/fuzz/CMakeLists.txt declares $expected" >&2
  idle=1
fi
# The harnesses run side by side, one per core, each for SECONDS.
fuzz_one() {
  local harness="$1" name corpus
  name=$(basename "$harness")
  corpus="$out/corpus/${name#fuzz_}"
  mkdir -p "$corpus" "$out/crashes/$name"
  cp "$root/tests/fuzz/corpus/${name#fuzz_}"/* "$corpus/" 2> /dev/null || true
  "$harness" -max_total_time="$seconds" -timeout=60 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$out/crashes/$name/" "$corpus" > "$out/$name.log" 2>&1 || true
}
for harness in "$build"/tests/fuzz/fuzz_*; do
  [ -x "$harness" ] || continue
  while [ "$(jobs -rp | wc -l)" -ge "$(nproc)" ]; do wait -n || true; done
  fuzz_one "$harness" &
done
wait
printf '%-22s %12s %8s\n' harness executions crashes
for harness in "$build"/tests/fuzz/fuzz_*; do
  [ -x "$harness" ] || continue
  name=$(basename "$harness")
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$out/$name.log" | grep -o '[0-9]*$' || echo 0)
  # libFuzzer also saves its slowest input (slow-unit-*): a note, not a finding.
  found=$(find "$out/crashes/$name" -type f ! -name 'slow-unit-*' | wc -l)
  printf '%-22s %12s %8s\n' "$name" "$runs" "$found"
  if [ "$runs" -eq 0 ]; then  # did not start, or ran nothing: no test at all
    echo "fuzz: $name ran no input (log: $out/$name.log)" >&2
    tail -5 "$out/$name.log" >&2
    idle=1
  fi
  total=$((total + runs)) crashed=$((crashed + found))
done
echo "total: $total executions, $crashed crashes (inputs and logs in $out)"
[ "$crashed" -eq 0 ] && [ "$idle" -eq 0 ]
