#!/usr/bin/env bash
# Every stage killed outright (kill -9 of make and everything it started) at
# seeded random moments of a dataset run; the next make then finishes the
# run, and its outputs are byte-identical to an uninterrupted run's. Left out
# of the comparison: what records wall-clock time (the training logs'
# elapsed_s, render/timing.json, vote/summary.json) and the logs.
# Usage: kill_stages.sh BIN_DIR [KILLS] [SEED]
source "$(dirname "${BASH_SOURCE[0]}")/../pipeline/test_lib.sh" "$1"
kills="${2:-8}" seed="${3:-1}"
"$bin/op2gs-synth" "$tmp/data/demo" --views 10 --width 96 --height 72 --supersample 1 --points 800 \
  > /dev/null 2>&1 || fail "op2gs-synth"
run=(DATASET=photos DATA_ROOT="$tmp/data" WORK_ROOT="$tmp/work" ITERATIONS=150 STAGE_ONE=100
     TRAIN_OPTS="--densify-until 0" CLIP="$root/tests/fixtures/tiny_clip" QUERIES="ball")
outputs() {
  (cd "$tmp/work" && find . -type f ! -path '*/logs/*' ! -path '*/stamps/*' ! -name '.op2gs*' \
     ! -name train_log.jsonl ! -name timing.json ! -path '*/vote/summary.json' -print0 |
     sort -z | xargs -0 sha1sum)
}

start=$(date +%s%N)
mk "${run[@]}" > "$tmp/reference.log" 2>&1 || { tail -5 "$tmp/reference.log"; fail "the reference run failed"; }
took_ms=$(( ($(date +%s%N) - start) / 1000000 ))
reference=$(outputs)
[ "$(wc -l <<< "$reference")" -gt 20 ] || fail "the reference run left too few outputs"

RANDOM=$seed
for ((k = 1; k <= kills; k++)); do
  rm -rf "$tmp/work"
  at_ms=$(( RANDOM % took_ms ))
  setsid make --no-print-directory -f "$root/pipeline/Makefile" BIN="$bin" "${run[@]}" \
    > "$tmp/killed.log" 2>&1 &
  leader=$!
  sleep "$(printf '%d.%03d' $((at_ms / 1000)) $((at_ms % 1000)))"
  kill -9 -- "-$leader" 2> /dev/null || true
  wait "$leader" 2> /dev/null || true
  # No stage line yet when the kill came before the first stage started.
  stage=$({ grep -o '== demo: [a-z]*$' "$tmp/killed.log" || true; } | tail -1 | sed 's/== demo: //')
  mk "${run[@]}" > "$tmp/after.log" 2>&1 || { tail -5 "$tmp/after.log"; fail "the run after kill $k failed"; }
  if [ "$(outputs)" != "$reference" ]; then
    diff <(echo "$reference") <(outputs) | head -5
    fail "kill $k at ${at_ms} ms (in stage ${stage:-none}): outputs differ from the uninterrupted run"
  fi
  echo "kill $k at ${at_ms} ms (in stage ${stage:-none yet}): outputs identical after the rerun"
done
echo "PASS"
