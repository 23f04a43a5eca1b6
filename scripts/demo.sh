#!/usr/bin/env bash
# Sets up (Debian packages + Release build) and runs the demo on the built-in
# synthetic scene. Until the stages after the foundation exist, the demo
# generates the synthetic demo scene (LERF-Mask layout) into demo/scene.
#
# Usage: scripts/demo.sh [output folder]   (default: demo/scene)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:-$root/demo/scene}"
"$root/scripts/setup.sh"
"$root/build/stages/op2gs-synth" "$out" --force
echo
echo "demo scene: $out"
echo "  images/ ($(ls "$out/images" | wc -l) views), sparse/0/ (true cameras), sam2/, instance_gt/, test_mask/"
