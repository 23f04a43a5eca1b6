#!/usr/bin/env python3
"""Tables of bench/studies/capture_study.sh's results.jsonl for docs/benchmarks.md.

    bench/studies/capture_study_table.py <out dir>/results.jsonl

Per (condition, variant): the mean over seeds of test PSNR (and the fitted
right-half PSNR), baseline and dual-opacity oracle mIoU / mBIoU, the margin,
and the objects where dual opacity falls more than 2 points below the
baseline; then the per-object mIoU of each condition's plain run. A line
repeated for one (condition, seed, variant) counts once (the last).
"""
import collections
import json
import os
import sys

rows = collections.OrderedDict()
for line in open(sys.argv[1]):
    r = json.loads(line)
    if "floaters" not in r:  # measured after the run: the work folder has it
        path = os.path.join(os.path.dirname(sys.argv[1]), f"{r['condition']}-{r['seed']}",
                            r["variant"], "floaters.json")
        if os.path.exists(path):
            f = json.load(open(path))
            r["floaters"] = {"region_opacity_share": f["region"]["floater_opacity_share"],
                             "mask_wrong_share": f["mask_wrong_share"]}
    if r.get("psnr_fitted") is None:
        path = os.path.join(os.path.dirname(sys.argv[1]), f"{r['condition']}-{r['seed']}",
                            r["variant"], "learn", "metrics.json")
        if os.path.exists(path):
            r["psnr_fitted"] = json.load(open(path)).get("psnr_fitted_right_half")
    rows[(r["condition"], r["seed"], r["variant"])] = r

groups = collections.OrderedDict()
for (condition, seed, variant), r in rows.items():
    groups.setdefault((condition, variant), []).append(r)


def mean(values):
    values = [v for v in values if v is not None]
    return sum(values) / len(values) if values else float("nan")


print("| condition | variant | seeds | test PSNR | fitted PSNR | floater opacity (region) "
      "| mask from wrong labels, sigma / sigma* | baseline mIoU / mBIoU "
      "| dual mIoU / mBIoU | margin | objects > 2 below the baseline |")
print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |")
for (condition, variant), rs in groups.items():
    base = mean([r["baseline"]["miou"] for r in rs])
    dual = mean([r["dual-opacity"]["miou"] for r in rs])
    below = collections.Counter()
    for r in rs:
        for name, d in r["dual-opacity"]["objects"].items():
            if d < r["baseline"]["objects"][name] - 2:
                below[name] += 1
    fl = [r["floaters"] for r in rs if "floaters" in r]
    print(f"| {condition} | {variant} | {len(rs)} | {mean([r['psnr'] for r in rs]):.2f} "
          f"| {mean([r.get('psnr_fitted') for r in rs]):.2f} "
          f"| {100 * mean([f['region_opacity_share'] for f in fl]):.1f}% "
          f"| {100 * mean([f['mask_wrong_share']['sigma'] for f in fl]):.1f}% / "
          f"{100 * mean([f['mask_wrong_share']['sigma_star'] for f in fl]):.1f}% "
          f"| {base:.1f} / {mean([r['baseline']['mbiou'] for r in rs]):.1f} "
          f"| {dual:.1f} / {mean([r['dual-opacity']['mbiou'] for r in rs]):.1f} "
          f"| {dual - base:+.1f} | {', '.join(f'{k} ({v})' for k, v in sorted(below.items())) or '-'} |")

print()
objects = sorted({o for r in rows.values() for o in r["dual-opacity"]["objects"]})
print("| condition (plain, mean over seeds) | " + " | ".join(objects) + " |")
print("| --- |" + " ---: |" * len(objects))
for (condition, variant), rs in groups.items():
    if variant != "plain":
        continue
    cells = []
    for o in objects:
        d = mean([r["dual-opacity"]["objects"].get(o) for r in rs])
        b = mean([r["baseline"]["objects"].get(o) for r in rs])
        cells.append(f"{d:.0f} / {b:.0f}")
    print(f"| {condition} (dual / baseline) | " + " | ".join(cells) + " |")
