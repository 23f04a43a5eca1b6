#!/usr/bin/env bash
# Stage two's targets on the default synthetic scene with its corrupted sam2/
# masks: the 30,000-iteration schedule scaled down by 4 in length (a 7,500
# iteration schedule: stage one to 5,000 with densification until 3,750 and
# the opacity reset at 3,000, the reference's intervals otherwise; voting;
# stage two from 5,000 to 7,500), then
#   - dual-opacity masks (S_j > 0.5) against the baseline label maps of the
#     same model, oracle mode of the LERF-Mask protocol (op2gs-eval);
#   - test PSNR against continuing stage one without the object loss;
#   - seconds per iteration of stage two with and without the object loss.
#
# A third argument scales the schedule down by another factor instead of 4
# (2: 15,000 iterations, stage one to 10,000).
#
#   bench/stage_two_bench.sh [build dir] [work dir] [scale]
set -euo pipefail
build="${1:-build}"
out="${2:-$(mktemp -d)}"
scale="${3:-4}"
total=$((30000 / scale))
stage_one=$((20000 / scale))
densify_until=$((15000 / scale))
mkdir -p "$out"
bin="$build/stages"
quiet() { "$@" 2>&1 | tr '\r' '\n' | grep -v '^\[[#-]'; }
[ -d "$out/scene" ] || "$bin/op2gs-synth" "$out/scene" > /dev/null
quiet "$bin/op2gs-train" "$out/scene" "$out/work" --iterations "$stage_one" --schedule "$total" \
  --densify-until "$densify_until"
quiet "$bin/op2gs-vote" "$out/scene" "$out/work"
cp -r "$out/work" "$out/control"
quiet "$bin/op2gs-learn" "$out/scene" "$out/work" --iterations "$total" --schedule "$total"
quiet "$bin/op2gs-learn" "$out/scene" "$out/control" --iterations "$total" --schedule "$total" \
  --lambda-o 0
quiet "$bin/op2gs-render" "$out/scene" "$out/work"
"$bin/op2gs-eval" "$out/scene" --pred dual-opacity="$out/work/render/masks" \
  --pred baseline="$out/work/render/baseline_labels" \
  --pred vote-baseline="$out/work/vote/baseline" --out "$out/metrics.json"
python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
def rate(log):
    r = [json.loads(l) for l in open(log) if '"elapsed_s"' in l]
    return (r[-1]["elapsed_s"] - r[0]["elapsed_s"]) / (r[-1]["iteration"] - r[0]["iteration"])
a, b = rate(f"{out}/work/learn/train_log.jsonl"), rate(f"{out}/control/learn/train_log.jsonl")
pa = json.load(open(f"{out}/work/learn/metrics.json"))["psnr"]
pb = json.load(open(f"{out}/control/learn/metrics.json"))["psnr"]
print(f"stage two: {1000*a:.1f} ms/iteration with the object loss, {1000*b:.1f} without: {a/b:.3f}x")
print(f"test PSNR: {pa:.2f} dB with the object loss, {pb:.2f} dB without ({pa-pb:+.2f} dB)")
PY
