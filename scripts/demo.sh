#!/usr/bin/env bash
# The one-command demo: installs the Debian packages and builds the stages (scripts/setup.sh),
# then runs every stage on the built-in synthetic scene with pipeline/Makefile
# (DATASET=synthetic), SfM included, and prints where the report is and the
# headline numbers:
#   op2gs-synth   the scene (photos, SAM2-like masks, ground truth), no model
#   op2gs-sfm     COLMAP: poses and sparse points from the photos
#   op2gs-train   stage one (3,000 iterations of a 4,500-iteration schedule)
#   op2gs-vote    labels by majority vote of the ID maps
#   op2gs-learn   stage two: sigma* with the random object loss (to 4,500)
#   op2gs-render  masks, label maps, colour of the test views
#   op2gs-embed / op2gs-query   CLIP object embeddings and text queries (the
#                 tiny test CLIP unless scripts/get_clip.sh fetched the real one)
#   op2gs-eval    mIoU / mBIoU, oracle and query mode; PSNR / SSIM
#   op2gs-report  HTML and Markdown report, 3D viewer of the labelled model
#
# Usage: scripts/demo.sh [WORK_DIR] [make options, e.g. -j2 or ITERATIONS=...]
# (default WORK_DIR: demo/ in the repository). Rerunning does only what is stale.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
work="$root/demo"
if [ $# -gt 0 ] && [[ "$1" != -* ]] && [[ "$1" != *=* ]]; then work="$1"; shift; fi
"$root/scripts/setup.sh" --stages-only
make -f "$root/pipeline/Makefile" DATASET=synthetic WORK_ROOT="$work" "$@"
