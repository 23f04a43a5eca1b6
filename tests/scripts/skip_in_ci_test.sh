#!/usr/bin/env bash
# The tests that skip where a tool is missing (Chromium, Slurm, a tmpfs
# mount) fail instead under CI=true, as .ci/run sets it: each is run with
# its tool taken off PATH, once as on a developer's machine (exit 77, ctest's
# skip) and once as in CI (exit 1 and a line saying why).
# Usage: skip_in_ci_test.sh BIN_DIR
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
bin="$1"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# A PATH with every command of this machine but the ones the tests skip without.
# The names are picked in bash and linked with one ln per folder: a fork per
# command (thousands on a machine with Chromium and Slurm) took most of a
# minute, the test's whole time limit, on a busy 2-core machine.
mkdir "$tmp/path"
declare -A seen
for dir in /usr/local/bin /usr/bin /bin /usr/sbin /sbin; do
  [ -d "$dir" ] || continue
  tools=()
  for tool in "$dir"/*; do
    name="${tool##*/}"
    case "$name" in
      chromium* | munged | slurmctld | slurmd | srun | sinfo | mount) continue ;;
    esac
    [ -n "${seen[$name]:-}" ] && continue
    seen[$name]=1
    tools+=("$tool")
  done
  [ ${#tools[@]} -eq 0 ] || ln -s -t "$tmp/path" -- "${tools[@]}"
done

# $1: the test's name; the rest: its command. Checks both exits.
check() {
  local name="$1" status
  shift
  status=0
  env -u CI PATH="$tmp/path" "$@" > "$tmp/$name.local" 2>&1 || status=$?
  [ "$status" -eq 77 ] || { cat "$tmp/$name.local"; fail "$name without its tool exited $status, not 77 (skipped)"; }
  grep -q '^SKIP: ' "$tmp/$name.local" || fail "$name skipped without saying why"
  status=0
  CI=true PATH="$tmp/path" "$@" > "$tmp/$name.ci" 2>&1 || status=$?
  [ "$status" -eq 1 ] || { cat "$tmp/$name.ci"; fail "$name without its tool under CI=true exited $status, not 1"; }
  grep -q 'FAIL: cannot run in CI' "$tmp/$name.ci" || fail "$name failed in CI without saying why"
  echo "ok: $name skips locally (77) and fails in CI (1)"
}

check report_viewer "$root/tests/eval/report/viewer_test.sh" "$bin" /bin/true
check pipeline_slurm "$root/tests/pipeline/slurm_test.sh" "$bin"
check reliability_disk_full "$root/tests/reliability/disk_full.sh" "$bin"
