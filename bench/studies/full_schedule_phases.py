#!/usr/bin/env python3
"""Groups a flat perf profile of a training run by phase.

Reads `perf report --no-children --sort dso,sym --stdio` and sums each
symbol's self time into the phase whose function it is, or was inlined into
(a parallel loop's body carries its enclosing function in its name). The
first matching rule wins; what matches none is listed under "other" with its
largest symbols, so that a new hot function shows up instead of vanishing.
"""
import re
import sys
from collections import defaultdict

PHASES = [
    ("projection backward", r"project_gaussians_backward|project_backward|backward_one|"
                            r"backward_color|backward_geometry|backward_batch|zero_gradients"),
    ("projection + SH colour", r"project_gaussians|project_geometry|project_extents|sh_basis|"
                               r"sh_colou?r|fast_exp"),
    ("binning (tile lists, depth sort)", r"bin_gaussians|radix_sort|depth_key|tile_bins"),
    ("rasterize forward", r"rasterize_forward|gather_with_blocks|TileGaussians|blend_block|"
                          r"pack_records"),
    ("rasterize backward", r"rasterize_backward|backward_tile|back_blocks|back_half|"
                           r"backward_band|sum_band_entries|number_band_entries|"
                           r"find_band_members"),
    ("loss (L1 + SSIM)", r"image_loss|ssim|blur|gaussian_window|psnr|rgb_channel|weighted_rows|"
                         r"split_channels|difference_sums"),
    ("Adam", r"GaussianAdam|adam_update"),
    ("densification", r"densify|DensificationStats|prune|reset_opacity|append_copy|max_scale"),
    ("object loss (stage two)", r"object_loss|sample_objects|instance_map"),
    ("data loading (decode, cache)", r"ViewCache|read_image|libpng|libjpeg|libz\.|png_|"
                                     r"inflate|jpeg_|OpenImageIO|decode|Imf|OIIO"),
    ("threading (TBB scheduler, idle)", r"libtbb|tbb::detail::r1|sched_yield|futex|"
                                        r"__sched_yield|do_sched_yield"),
    ("memory (page faults, memset, memcpy, malloc)", r"\[kernel|clear_page|memset|memcpy|"
                                                     r"memmove|page_fault|malloc|_int_free|"
                                                     r"unlink_chunk|madvise"),
]


def parse(lines):
    """(percent, dso, symbol) for each row of perf's table."""
    row = re.compile(r"^\s*([0-9.]+)%\s+(\S+)\s+\[[^\]]+\]\s+(.*)$")
    for line in lines:
        m = row.match(line)
        if m:
            yield float(m.group(1)), m.group(2), m.group(3).strip()


def main():
    totals = defaultdict(float)
    other = defaultdict(float)
    for pct, dso, sym in parse(sys.stdin):
        text = f"{dso} {sym}"
        for name, pattern in PHASES:
            if re.search(pattern, text):
                totals[name] += pct
                break
        else:
            totals["other"] += pct
            other[text[:110]] += pct
    for name, _ in PHASES + [("other", "")]:
        if totals[name] >= 0.05:
            print(f"{totals[name]:6.1f}%  {name}")
    for text, pct in sorted(other.items(), key=lambda kv: -kv[1])[:8]:
        print(f"          other: {pct:5.1f}%  {text}")


if __name__ == "__main__":
    main()
