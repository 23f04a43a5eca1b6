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
mk() { make --no-print-directory -f "$root/pipeline/Makefile" BIN="$bin" "$@"; }
