#!/usr/bin/env bash
# Times op2gs-synth on the two sizes the foundation issue names and prints
# wall time and peak memory (the stage reports its own peak RSS).
#
#   bench/synth_bench.sh [build dir]
set -euo pipefail
build="${1:-build}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
for size in "40 320 240" "60 640 480"; do
  # shellcheck disable=SC2086  # the three numbers, split on purpose
  set -- $size
  start=$(date +%s.%N)
  log=$("$build/stages/op2gs-synth" "$out/s_$1" --views "$1" --width "$2" --height "$3" 2>&1)
  end=$(date +%s.%N)
  peak=$(echo "$log" | sed -n 's/.*peak memory \([0-9]*\) MiB.*/\1/p')
  printf '%s views %sx%s: %.1f s, peak %s MiB\n' "$1" "$2" "$3" "$(awk -v a="$start" -v b="$end" "BEGIN{print b-a}")" "$peak"
done
