#!/usr/bin/env bash
# Stage one on the default synthetic scene with its true poses: the trainer
# issue's target (>= 30 dB test PSNR within 7,000 iterations, under 10 minutes
# on the 2-core build machine). Prints the stage's own summary (time, test
# PSNR / SSIM, Gaussians, peak memory).
#
#   bench/train_bench.sh [build dir] [iterations]
set -euo pipefail
build="${1:-build}"
iterations="${2:-7000}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
"$build/stages/op2gs-synth" "$out/scene" > /dev/null
"$build/stages/op2gs-train" "$out/scene" "$out/work" --iterations "$iterations" \
  --test-at 1000 2000 3000 4000 5000 6000 2>&1 | tr '\r' '\n' | grep -v '^\[[#-]'
grep test_psnr "$out/work/train_log.jsonl"
