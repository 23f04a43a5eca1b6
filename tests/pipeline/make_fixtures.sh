#!/usr/bin/env bash
# Writes folders that mimic the real LERF-Mask and 3DOVS downloads (scene and
# file names, test views, query and class lists; the images are one small
# PNG copied everywhere), to check the dataset definitions against.
# Usage: make_fixtures.sh PNG OUT
set -euo pipefail
png="$1" out="$2"
rm -rf "$out"

lerf_scene() {  # name views test_views query...
  local d="$out/lerf_mask/$1" views="$2" tests="$3"
  shift 3
  mkdir -p "$d/images" "$d/images_train" "$d/sparse/0" "$d/sam2"
  local i k=0
  for ((i = 1; i <= views; i++)); do
    local f; f=$(printf 'frame_%05d.jpg' "$i")
    cp "$png" "$d/images/$f"
    cp "$png" "$d/sam2/${f%.jpg}.png"
    # The test views are spread over the sequence.
    if (( (i - 1) % (views / tests) == 0 && k < tests )); then
      k=$((k + 1))
    else
      cp "$png" "$d/images_train/$f"
    fi
  done
  for ((i = 0; i < tests; i++)); do
    mkdir -p "$d/test_mask/$i"
    for q in "$@"; do cp "$png" "$d/test_mask/$i/$q.png"; done
  done
}
lerf_scene figurines 30 3 "green apple" "green toy chair" "old camera" "porcelain hand" \
  "red apple" "red toy chair" "rubber duck with red hat"
lerf_scene ramen 30 3 chopsticks egg "glass of water" "pork belly" "wavy noodles in bowl" \
  "yellow bowl"
lerf_scene teatime 30 3 apple "bag of cookies" "coffee mug" "cookies on a plate" \
  "paper napkin" plate sheep "spoon handle" "stuffed bear" "tea in a glass"

for scene in bed bench blue_sofa covered_desk lawn office_desk room snacks sofa table; do
  d="$out/3dovs/$scene"
  mkdir -p "$d/images" "$d/sam2" "$d/segmentations"
  for ((i = 0; i < 30; i++)); do
    cp "$png" "$d/images/$(printf '%02d' "$i").jpg"
    cp "$png" "$d/sam2/$(printf '%02d' "$i").png"
  done
  : > "$d/poses_bounds.npy"
  printf 'banana\nblack leather shoe\ncamera\nhand\nred bag\nwhite sheet\n' > "$d/segmentations/classes.txt"
  for v in 00 06 12 18 24; do
    mkdir -p "$d/segmentations/$v"
    for c in banana camera "red bag" "white sheet"; do cp "$png" "$d/segmentations/$v/$c.png"; done
  done
done
