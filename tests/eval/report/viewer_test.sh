#!/usr/bin/env bash
# The report's 3D viewer, tested as a person would look at it: a tiny scene
# through the pipeline, its report's viewer served over HTTP and opened in
# headless Chromium (software WebGL), screenshots from the training camera it
# starts at compared
# with op2gs-render's images of that camera, isolating one object, and the
# PLY the page cuts compared with op2gs-render --ply-object's.
# Skipped (77) when Chromium or python3 is missing; in CI that fails.
# Usage: viewer_test.sh BIN_DIR VIEWER_CHECK
source "$(dirname "${BASH_SOURCE[0]}")/../../pipeline/test_lib.sh"
check="$2"
chromium=$(command -v chromium || command -v chromium-browser || true)
[ -n "$chromium" ] || skip "no chromium (scripts/setup.sh --tests installs it)"
command -v python3 > /dev/null || skip "no python3 to serve the page"

echo "-- a tiny scene through every stage, the report with its viewer"
tiny_lerf_run "$tmp/run"
mk "${run[@]}" > "$tmp/make.log" 2>&1 || { tail -20 "$tmp/make.log"; fail "the tiny run failed"; }
w="$tmp/run/demo"
viewer="$w/report/viewer/demo"
for f in index.html viewer.js model.spz gaussians.bin model.ply scene.json ../vendor.min.js; do
  [ -s "$viewer/$f" ] || fail "the report has no viewer/demo/$f"
done
grep -q 'viewer/demo/index.html' "$w/report/report.html" || fail "the report does not link the viewer"
grep -qE 'https?://' "$viewer/index.html" "$viewer/viewer.js" && fail "the page names an internet address"

mkdir -p "$tmp/posted"
python3 "$root/tests/eval/report/serve.py" "$w/report" "$tmp/posted" > "$tmp/port" &
server=$!
trap 'kill $server 2> /dev/null; rm -rf "$tmp"' EXIT
until [ -s "$tmp/port" ]; do sleep 0.1; done
port=$(cat "$tmp/port")

# The first training view (where the page starts), rendered by op2gs-render;
# the page's RGB, labels with sigma*, and one object isolated from there.
camera=$(tr -d '\n ' < "$viewer/scene.json" | grep -o '"name":"[^"]*","t":\[[^]]*\],"test":false' |
         head -1 | sed 's/"name":"\([^"]*\)".*/\1/')
[ -n "$camera" ] || fail "scene.json lists no training camera"
"$bin/op2gs-render" "$w/sfm/scene" "$w" --view "$camera" --out "$tmp/train_render" \
  > "$tmp/render.log" 2>&1 || { tail -5 "$tmp/render.log"; fail "op2gs-render --view $camera"; }
view="${camera%.*}.png"
renders="$tmp/train_render"
object=$(sed -n 's/.*"object": \([1-9][0-9]*\).*/\1/p' "$w/eval/metrics.json" | head -1)
url="http://127.0.0.1:$port/viewer/demo/index.html?shots=rgb,dual,dual@$object"
url+="&capture=/shot&log=/log&extract=$object&extract_to=/object.ply"
echo "-- headless Chromium on $url"
"$chromium" --headless=new --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader \
  --force-device-scale-factor=1 --window-size=1200,900 --user-data-dir="$tmp/profile" \
  --remote-debugging-port=0 "$url" > "$tmp/chromium.log" 2>&1 &
browser=$!
for ((s = 0; s < 240; s++)); do
  [ -s "$tmp/posted/shot2.png" ] && break
  grep -q "error" "$tmp/posted/log" 2> /dev/null && break
  sleep 0.5
done
kill "$browser" 2> /dev/null || true
wait "$browser" 2> /dev/null || true
cat "$tmp/posted/log" 2> /dev/null | sed 's/^/   page: /'
[ -s "$tmp/posted/shot2.png" ] || fail "the page did not capture its views in 120 s"

"$check" rgb "$tmp/posted/shot0.png" "$renders/rgb/$view" 25
"$check" labels "$tmp/posted/shot1.png" "$renders/instance_labels_color/$view" 0.75
"$check" isolate "$tmp/posted/shot2.png" "$renders/instance_labels_color/$view" "$object" 0.8

"$bin/op2gs-render" "$w/sfm/scene" "$w" --ply-object "$object" --ply-out "$tmp/render_object.ply" \
  > /dev/null 2>&1 || fail "op2gs-render --ply-object"
cmp -s "$tmp/posted/object.ply" "$tmp/render_object.ply" ||
  fail "the page's object PLY differs from op2gs-render --ply-object's"
echo "ok: the page's PLY of object $object is op2gs-render's, byte for byte"
echo PASS
