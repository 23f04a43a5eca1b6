#!/usr/bin/env python3
"""The schedule's estimated time from sampled rates (bench/studies/full_schedule.sh).

Reads lines "K seconds-per-iteration" (or, with --paired, "K old1 old2 new1
new2"; with --threads the same, old being 1 thread and new 2) and integrates the rate over the schedule: linearly between the
sampled iterations of a stage, constant from a stage's last sample to its end
(densification stops at 15,000, so stage one's Gaussians stop changing
there; stage two never densifies). Stage one is 0..20,000, stage two
20,000..30,000, as in the paper.
"""
import sys

STAGES = (("stage one", 0, 20000), ("stage two", 20000, 30000))


def integrate(points, start, end):
    """Seconds for iterations start..end from {iteration: rate}, or None."""
    ks = sorted(k for k in points if start <= k < end)
    if not ks or ks[0] != start:
        return None
    total = 0.0
    for a, b in zip(ks, ks[1:]):
        total += (b - a) * (points[a] + points[b]) / 2
    return total + (end - ks[-1]) * points[ks[-1]]


def estimate(points):
    parts, total = [], 0.0
    for name, start, end in STAGES:
        s = integrate(points, start, end)
        if s is None:
            parts.append(f"{name}: no sample at {start}")
            total = None
            continue
        parts.append(f"{name} {s / 3600:.2f} h")
        if total is not None:
            total += s
    return total, parts


def main():
    paired = "--paired" in sys.argv or "--threads" in sys.argv
    scaling = "--threads" in sys.argv  # old: 1 thread, new: 2
    old, new = {}, {}
    for line in sys.stdin:
        f = line.split()
        if not f:
            continue
        k = int(f[0])
        if paired:
            a1, a2, b1, b2 = map(float, f[1:5])
            old[k], new[k] = (a1 + a2) / 2, (b1 + b2) / 2
            print(f"{k:>6}: old {1000 * old[k]:8.1f} ms/it, new {1000 * new[k]:8.1f} ms/it, "
                  f"new/old {new[k] / old[k]:.3f} (runs {b1 / a1:.3f}, {b2 / a2:.3f})")
        else:
            old[k] = float(f[1])
            print(f"{k:>6}: {1000 * old[k]:8.1f} ms/iteration")
    for name, points in (("old", old), ("new", new)) if paired else (("estimate", old),):
        total, parts = estimate(points)
        head = f"{name}: {total / 3600:.2f} h for 30,000 iterations" if total else f"{name}: partial"
        print(f"{head} ({'; '.join(parts)})")
    if paired:
        t_old, _ = estimate(old)
        t_new, _ = estimate(new)
        if t_old and t_new and scaling:
            print(f"speed-up of 2 threads over 1 over the schedule: {t_old / t_new:.3f}")
        elif t_old and t_new:
            print(f"new/old over the schedule: {t_new / t_old:.3f}")
        else:  # the stages that have every sample
            for name, start, end in STAGES:
                a, b = integrate(old, start, end), integrate(new, start, end)
                if a and b:
                    print(f"{name} new/old (sampled part): {b / a:.3f}")


if __name__ == "__main__":
    main()
