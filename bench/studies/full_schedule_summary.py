#!/usr/bin/env python3
"""What bench/studies/full_schedule.sh's full run has done so far: DIR/full.

The run may have been interrupted and resumed (a session ends, a machine
restarts): each resumed run starts its clock again and keeps the log's
records up to its checkpoint, so a stage's time is the sum of the last
elapsed time of each run in its log (work lost after the last checkpoint of
an interrupted run is not counted; segments.log has the wall times with it).
"""
import json
import os
import re
import sys

STAGES = (("stage one", "train_log.jsonl", "metrics.json"),
          ("stage two", "learn/train_log.jsonl", "learn/metrics.json"))


def read_log(path):
    rows = []
    with open(path) as f:
        for line in f:
            try:
                r = json.loads(line)
            except json.JSONDecodeError:
                continue  # a partial last line of a killed run
            if "elapsed_s" in r:
                rows.append(r)
    return rows


def stage_seconds(rows):
    """Sum of each run's last elapsed time (the clock restarts on resume)."""
    total, last = 0.0, 0.0
    for r in rows:
        if r["elapsed_s"] < last:
            total += last
        last = r["elapsed_s"]
    return total + last


def rates(rows, every=2500):
    """Seconds per iteration over each window of `every` iterations."""
    out, by_it = [], {r["iteration"]: r for r in rows}
    first = rows[0]["iteration"]
    for end in range(first - first % every + every, rows[-1]["iteration"] + 1, every):
        a, b = by_it.get(end - every + 1), by_it.get(end)
        if a and b and b["elapsed_s"] > a["elapsed_s"]:
            out.append(f'{end}: {(b["elapsed_s"] - a["elapsed_s"]) / (every - 1):.3f}')
    return out


def peak_memory(segments, name):
    peaks = [int(m.group(1)) for m in re.finditer(rf"^{name}: [\d.]+ s, peak (\d+) KiB", segments,
                                                  re.M)]
    return f"{max(peaks) / 1024:.0f} MiB" if peaks else "not recorded"


def main():
    full = sys.argv[1]
    seg_path = os.path.join(full, "segments.log")
    segments = open(seg_path).read() if os.path.exists(seg_path) else ""
    for line in segments.splitlines():
        print(line)
    for name, log, metrics in STAGES:
        path = os.path.join(full, log)
        if not os.path.exists(path):
            print(f"{name}: not started")
            continue
        rows = read_log(path)
        if not rows:
            print(f"{name}: no iteration yet")
            continue
        marks = [r for r in rows if r["iteration"] % 2500 == 0 or r is rows[-1]]
        print(f'{name}: {rows[-1]["iteration"]} iterations, {stage_seconds(rows):.0f} s of '
              f'training, peak memory {peak_memory(segments, name)}')
        print(f"{name} Gaussians: " + ", ".join(f'{r["iteration"]}: {r["gaussians"]}' for r in marks))
        print(f"{name} s/iteration (2,500-iteration windows): " + ", ".join(rates(rows)))
        m = os.path.join(full, metrics)
        if os.path.exists(m):
            j = json.load(open(m))
            print(f'{name} test PSNR at {j["iteration"]}: {j["psnr"]:.2f} dB, SSIM {j["ssim"]:.4f}')


if __name__ == "__main__":
    main()
