#!/usr/bin/env bash
# Paired timings of two builds (for example before and after a change): the
# renderer, a voting run and a short stage-one training run, each run
# alternately with the two builds' binaries so that drift of the machine hits
# both alike. Prints every run and the median of each, with its unit.
#
#   bench/paired.sh OLD_BUILD NEW_BUILD [rounds] [training iterations]
set -euo pipefail
old="$1" new="$2"
rounds="${3:-3}"
iterations="${4:-500}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

"$new/stages/op2gs-synth" "$tmp/scene" > /dev/null

render_filter='BM_Forward/200000/1/1/real_time|BM_ForwardBackward/200000/1/1/real_time|BM_AllObjectMasksOnly/200000/1/1/real_time'
vote_filter='BM_Vote/gaussians:200000/views:60/frustum_only:0'

# Prints "name milliseconds" lines for one build.
run_build() {
  local build="$1"
  "$build/bench/render_bench" --benchmark_filter="$render_filter" --benchmark_repetitions=3 \
    --benchmark_report_aggregates_only=true --benchmark_format=csv 2> /dev/null |
    awk -F, '/_median/ { gsub(/"/, "", $1); print $1 "[" $5 "]", $3 }'
  "$build/bench/vote_bench" --benchmark_filter="$vote_filter" --benchmark_format=csv 2> /dev/null |
    awk -F, '/BM_Vote/ { gsub(/"/, "", $1); print $1 "[" $5 "]", $3 }'
  rm -rf "$tmp/work"
  local start end
  start=$(date +%s.%N)
  "$build/stages/op2gs-train" "$tmp/scene" "$tmp/work" --iterations "$iterations" \
    --schedule 30000 > /dev/null 2>&1
  end=$(date +%s.%N)
  echo "op2gs-train/${iterations}_iterations[s] $(echo "$end - $start" | bc)"
}

for _ in $(seq "$rounds"); do
  run_build "$old" | sed "s/^/old /"
  run_build "$new" | sed "s/^/new /"
done | tee "$tmp/runs.txt"

echo
echo "median: benchmark[unit], old, new, new/old"
awk '{ v[$2 " " $1] = v[$2 " " $1] " " $3; names[$2] = 1 }
     END { for (n in names) print n, v[n " old"], "|", v[n " new"] }' "$tmp/runs.txt" |
  while read -r name rest; do
    o=$(echo "${rest%|*}" | tr ' ' '\n' | sed '/^$/d' | sort -g | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }')
    n=$(echo "${rest#*|}" | tr ' ' '\n' | sed '/^$/d' | sort -g | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }')
    printf '%s %.2f %.2f %.3f\n' "$name" "$o" "$n" "$(echo "$n / $o" | bc -l)"
  done
