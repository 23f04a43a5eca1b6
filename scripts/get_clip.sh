#!/usr/bin/env bash
# Downloads the CLIP ViT-B/16 files op2gs-embed and op2gs-query need (once,
# ~600 MB) from the Hugging Face release openai/clip-vit-base-patch16 into
# DIR (default: $OP2GS_CLIP_DIR, else ~/.cache/op2gs/clip-vit-base-patch16),
# the folder both stages look in by default. Needs wget or curl.
#
# The release's main branch ships pytorch_model.bin; its safetensors file sits
# on the branch refs/pr/10. When that cannot be fetched, the script downloads
# pytorch_model.bin and converts it with scripts/clip_to_safetensors.py
# (Debian's python3-torch).
#
# Usage: scripts/get_clip.sh [DIR]
set -euo pipefail

dir="${1:-${OP2GS_CLIP_DIR:-$HOME/.cache/op2gs/clip-vit-base-patch16}}"
base="https://huggingface.co/openai/clip-vit-base-patch16/resolve"
mkdir -p "$dir"

fetch() {  # URL FILE
  if command -v wget >/dev/null; then wget -q --show-progress -O "$2.part" "$1"
  else curl -fL --progress-bar -o "$2.part" "$1"; fi && mv "$2.part" "$2"
}

for f in config.json vocab.json merges.txt; do
  [ -s "$dir/$f" ] || fetch "$base/main/$f" "$dir/$f"
done
if [ ! -s "$dir/model.safetensors" ]; then
  if ! fetch "$base/refs%2Fpr%2F10/model.safetensors" "$dir/model.safetensors"; then
    echo "get_clip: no model.safetensors on refs/pr/10; converting pytorch_model.bin" >&2
    fetch "$base/main/pytorch_model.bin" "$dir/pytorch_model.bin"
    /usr/bin/python3 "$(dirname "$0")/clip_to_safetensors.py" "$dir/pytorch_model.bin" \
      "$dir/model.safetensors"
  fi
fi
echo "CLIP files in $dir"
