# What the pipeline test scripts share; sourced with the binaries' folder as $1.
# Sets root (the checkout), bin, tmp (removed on exit); fail and mk (make with
# pipeline/Makefile and these binaries).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
bin="$(cd "$1" && pwd)"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# set -e exits without a word; say which command stopped the test.
trap 'echo "FAIL: ${BASH_SOURCE[0]:-$0}:$LINENO: $BASH_COMMAND exited with $?" >&2' ERR
fail() { echo "FAIL: $*" >&2; exit 1; }
# A test that cannot run here (a tool missing, a daemon that does not start)
# is skipped: exit 77, which ctest reports as "Not Run". In CI (CI=true),
# where scripts/test.sh installed everything, it fails instead: a test that
# cannot run there is broken, not optional.
skip() {
  if [ "${CI:-}" = true ]; then
    echo "FAIL: cannot run in CI (CI=true): $*" >&2
    exit 1
  fi
  echo "SKIP: $*"
  exit 77
}
mk() { make --no-print-directory -f "$root/pipeline/Makefile" BIN="$bin" "$@"; }

# A tiny scene shaped as a LERF-Mask download in $tmp/data/demo, so that every
# stage runs, queries and evaluation included; sets `run` to the make
# variables of a short dataset run over it with its work folder in $1. Its
# COLMAP model is imported: COLMAP's own SfM is not deterministic under
# threads.
tiny_lerf_run() {
  "$bin/op2gs-synth" "$tmp/data/demo" --as lerf-mask-download --views 10 --width 96 --height 72 \
    --supersample 1 --points 800 --test-every 4 > /dev/null 2>&1 || fail "op2gs-synth"
  local queries
  queries=$(find "$tmp/data/demo/test_mask" -name '*.png' -printf '%f\n' | sed 's/\.png$//' |
            sort -u | paste -sd ';')
  run=(DATASET=lerf-mask DATA_ROOT="$tmp/data" WORK_ROOT="$1" SCENES=demo "QUERIES_demo=$queries"
       ITERATIONS=150 STAGE_ONE=100 TRAIN_OPTS="--densify-until 0" CLIP="$root/tests/fixtures/tiny_clip")
}

# Checksums of every output in work folder $1, without what records
# wall-clock time (the training logs' elapsed_s, render/timing.json,
# vote/summary.json), the logs and make's stamps.
work_outputs() {
  (cd "$1" && find . -type f ! -path '*/logs/*' ! -path '*/stamps/*' ! -name '.op2gs*' \
     ! -name '*.log' ! -name train_log.jsonl ! -name timing.json ! -path '*/vote/summary.json' \
     -print0 | sort -z | xargs -0 sha1sum)
}
