#!/usr/bin/env bash
# Times opening the report's 3D viewer of an N-Gaussian model (default one
# million) in headless Chromium: from the page's request to its "N Gaussians"
# status line (model.spz fetched and decoded by Spark, labels read, the three
# views built), and to its first settled picture. Software WebGL (SwiftShader)
# draws far slower than any GPU; the load time is the browser's CPU work.
#
#   bench/studies/viewer_open.sh [build dir] [N]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:-$root/build}" n="${2:-1000000}"
tmp=$(mktemp -d)
trap 'kill $(jobs -p) 2> /dev/null; rm -rf "$tmp"' EXIT
"$build/stages/op2gs-synth" "$tmp/scene" --views 4 --width 320 --height 240 > /dev/null 2>&1
"$build/bench/viewer_bench" "$tmp/scene" "$tmp/out" "$n"
mkdir -p "$tmp/posted"
python3 "$root/tests/eval/report/serve.py" "$tmp/out" "$tmp/posted" > "$tmp/port" &
until [ -s "$tmp/port" ]; do sleep 0.1; done
camera=$(sed -n 's/.*"name": "\([^"]*\)".*/\1/p' "$tmp/out/viewer/bench/scene.json" | head -1)
start=$(date +%s.%N)
chromium --headless=new --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader \
  --force-device-scale-factor=1 --user-data-dir="$tmp/profile" --remote-debugging-port=0 \
  "http://127.0.0.1:$(cat "$tmp/port")/viewer/bench/index.html?camera=$camera&capture=/shot&log=/log" \
  > /dev/null 2>&1 &
loaded=""
for ((s = 0; s < 1200; s++)); do
  if [ -z "$loaded" ] && grep -q "Gaussians, " "$tmp/posted/log" 2> /dev/null; then
    loaded=$(date +%s.%N)
  fi
  [ -s "$tmp/posted/shot0.png" ] && break
  sleep 0.1
done
shot=$(date +%s.%N)
[ -n "$loaded" ] || { cat "$tmp/posted/log" 2> /dev/null; echo "the page did not load"; exit 1; }
sed "s/^/   page: /" "$tmp/posted/log"
awk -v a="$start" -v b="$loaded" -v c="$shot" -v n="$n" \
  'BEGIN { printf "%d Gaussians: loaded in %.1f s, first settled picture (12 frames) at %.1f s\n", n, b - a, c - a }'
