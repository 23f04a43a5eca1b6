#!/usr/bin/python3
"""Converts a Hugging Face CLIP checkpoint (pytorch_model.bin) to model.safetensors.

op2gs reads CLIP weights in the safetensors layout only. The tensor names are
kept as they are (text_model.*, vision_model.*, visual_projection.weight,
text_projection.weight); integer buffers (position_ids) are dropped.
Needs Debian's python3-torch. Usage:
  /usr/bin/python3 scripts/clip_to_safetensors.py pytorch_model.bin model.safetensors
"""

import json
import os
import struct
import sys

import torch


def main():
    source, target = sys.argv[1], sys.argv[2]
    state = torch.load(source, map_location="cpu")
    header, offset, names = {}, 0, []
    for name in sorted(state):
        t = state[name]
        if not t.is_floating_point():
            continue
        size = t.numel() * 4
        header[name] = {"dtype": "F32", "shape": list(t.shape), "data_offsets": [offset, offset + size]}
        offset += size
        names.append(name)
    text = json.dumps(header, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 8)
    tmp = target + ".part"
    with open(tmp, "wb") as f:
        f.write(struct.pack("<Q", len(text)))
        f.write(text)
        for name in names:
            f.write(state[name].float().contiguous().numpy().astype("<f4").tobytes())
    os.replace(tmp, target)
    print(f"{len(names)} tensors written to {target}")


if __name__ == "__main__":
    main()
