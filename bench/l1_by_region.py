#!/usr/bin/python3
"""Where the ring's annulus-mass L1 comes from (docs/validation.md, "The mixed gradient correction"):
splits it over the inner wing (r < 0.5 r0), the core (0.5-1.5 r0) and the outer wing (r > 1.5 r0),
each beside the part of the binomial sampling floor from the same bins, and prints every bin's
count deviation in binomial standard deviations (z). Reads the JSON that `sphdisk analyze --json`
(or bench/ring_convergence.py, as snapshot_NNN_analysis.json) writes.

Usage: bench/l1_by_region.py ANALYSIS.json [...] [--bins]
"""
import json
import math
import sys

REGIONS = (("inner", 0.0, 0.5), ("core", 0.5, 1.5), ("outer", 1.5, math.inf))


def split(path):
    d = json.load(open(path))
    n, mass = d["particles"], d["initial_mass"]
    parts = {name: [0.0, 0.0] for name, _, _ in REGIONS}
    zs = []
    for b in d["bins"]:
        p = b["sigma_ana_annulus"] * math.pi * (b["r_hi"] ** 2 - b["r_lo"] ** 2) / mass  # a particle's chance
        expected = n * p
        r = 0.5 * (b["r_lo"] + b["r_hi"])
        name = next(name for name, lo, hi in REGIONS if lo <= r < hi)
        parts[name][0] += abs(b["count"] - expected) / n
        parts[name][1] += math.sqrt(2 / math.pi * expected * (1 - p)) / n  # E|binomial - mean|, normal limit
        if expected >= 5:
            zs.append((r, (b["count"] - expected) / math.sqrt(expected * (1 - p))))
    return d, parts, zs


def main():
    paths = [a for a in sys.argv[1:] if not a.startswith("--")]
    if not paths:
        sys.exit(__doc__)
    for path in paths:
        d, parts, zs = split(path)
        cells = "  ".join(f"{name} {l1:.4f} / {floor:.4f} ({l1 / floor:.1f}x)" for name, (l1, floor) in parts.items())
        print(f"{path}: N {d['particles']}, tau {d['tau']:.4g}; L1 / floor by region: {cells}")
        if "--bins" in sys.argv:
            print("  z by bin: " + " ".join(f"{r:.2f}:{z:+.1f}" for r, z in zs))


if __name__ == "__main__":
    main()
