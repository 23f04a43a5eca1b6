#!/usr/bin/env bash
# Checks a dataset's scene folders against its definition before a long run:
# the files every stage needs, the test views, and the query lists.
# One line per problem, naming the file; exits 1 when any scene has one.
#
# Usage: check_dataset.sh LAYOUT DATA_ROOT 'SCENE=query;query;...' ...
#   LAYOUT: lerf-mask, 3dovs or photos
set -uo pipefail
layout="$1" root="$2"
shift 2
problems=0
problem() { echo "check: $1" >&2; problems=$((problems + 1)); }

images_of() { find "$1" -maxdepth 1 -type f \( -iname '*.png' -o -iname '*.jpg' -o -iname '*.jpeg' \) -printf '%f\n' | sort; }

check_common() {  # scene folder
  local d="$1"
  [ -d "$d" ] || { problem "$d: no such scene folder"; return 1; }
  [ -d "$d/images" ] && [ -n "$(images_of "$d/images")" ] || problem "$d/images: missing or holds no PNG/JPEG images"
  [ -d "$d/sam2" ] || problem "$d/sam2: missing (the ID maps op2gs-vote needs, one per image)"
  if [ -d "$d/sam2" ] && [ -d "$d/images" ]; then
    local missing=0
    while read -r f; do
      [ -n "$f" ] && [ ! -e "$d/sam2/${f%.*}.png" ] && missing=$((missing + 1))
    done < <(images_of "$d/${train_dir:-images}")
    [ "$missing" -eq 0 ] || problem "$d/sam2: $missing training views have no ID map <stem>.png"
  fi
}

check_lerf_mask() {  # scene folder, expected queries (;-separated, may be empty)
  local d="$1" expected="$2"
  train_dir=images_train check_common "$d" || return
  [ -d "$d/sparse/0" ] || echo "check: $d/sparse/0: no COLMAP model; op2gs-sfm will make one" >&2
  [ -d "$d/images_train" ] || { problem "$d/images_train: missing (the training views)"; return; }
  while read -r f; do
    [ -n "$f" ] && [ ! -e "$d/images/$f" ] && problem "$d/images_train/$f: not in images/"
  done < <(images_of "$d/images_train")
  local tests=$(( $(images_of "$d/images" | wc -l) - $(images_of "$d/images_train" | wc -l) ))
  [ "$tests" -gt 0 ] || problem "$d: no test views (every image of images/ is in images_train/)"
  [ -d "$d/test_mask" ] || { problem "$d/test_mask: missing (the ground truth)"; return; }
  local k found=""
  for k in "$d"/test_mask/*/; do
    k=$(basename "$k")
    [[ "$k" =~ ^[0-9]+$ ]] || { problem "$d/test_mask/$k: not a test view index"; continue; }
    [ "$((10#$k))" -lt "$tests" ] || problem "$d/test_mask/$k: only $tests test views"
    found+=$(find "$d/test_mask/$k" -maxdepth 1 -name '*.png' -printf '%f\n' | sed 's/\.png$//')$'\n'
  done
  found=$(printf '%s' "$found" | sed '/^$/d' | sort -u)
  if [ -n "$expected" ]; then
    local want
    want=$(printf '%s\n' "$expected" | tr ';' '\n' | sed '/^$/d' | sort -u)
    [ "$found" = "$want" ] || problem "$d/test_mask: queries differ from the dataset's list: $(diff <(echo "$want") <(echo "$found") | grep '^[<>]' | sed 's/^</missing:/; s/^>/extra:/' | paste -sd, -)"
  fi
  echo "check: $d: $tests test views, $(echo "$found" | sed '/^$/d' | wc -l) queries"
}

check_3dovs() {  # scene folder
  local d="$1"
  check_common "$d" || return
  [ -e "$d/poses_bounds.npy" ] || [ -d "$d/sparse/0" ] || problem "$d/poses_bounds.npy: missing (the LLFF cameras)"
  local classes="$d/segmentations/classes.txt"
  [ -f "$classes" ] || { problem "$classes: missing"; return; }
  local n_images views=0 v
  n_images=$(images_of "$d/images" | wc -l)
  for v in "$d"/segmentations/*/; do
    v=$(basename "$v")
    [[ "$v" =~ ^[0-9]+$ ]] || { problem "$d/segmentations/$v: not an image index"; continue; }
    [ "$((10#$v))" -lt "$n_images" ] || problem "$d/segmentations/$v: only $n_images images"
    views=$((views + 1))
    while read -r m; do
      [ -n "$m" ] && ! grep -qxF "${m%.png}" <(tr -d '\r' < "$classes") &&
        problem "$d/segmentations/$v/$m: not a class of classes.txt"
    done < <(find "$d/segmentations/$v" -maxdepth 1 -name '*.png' -printf '%f\n')
  done
  [ "$views" -gt 0 ] || problem "$d/segmentations: no segmented views"
  echo "check: $d: $views segmented views, $(sed '/^\s*$/d' "$classes" | wc -l) classes"
}

for entry in "$@"; do
  scene="${entry%%=*}" queries="${entry#*=}"
  case "$layout" in
    lerf-mask) check_lerf_mask "$root/$scene" "$queries" ;;
    3dovs) check_3dovs "$root/$scene" ;;
    *) check_common "$root/$scene" ;;
  esac
done
if [ "$problems" -gt 0 ]; then
  echo "check: $problems problem(s)" >&2
  exit 1
fi
echo "check: every scene is complete"
