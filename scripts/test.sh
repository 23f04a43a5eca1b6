#!/usr/bin/env bash
# Sets up (Debian packages + Release build) and runs the whole test suite.
# Exits non-zero when any test fails.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/setup.sh" --tests "$@"
ctest --test-dir "$root/build" --output-on-failure --parallel "$(nproc)"
