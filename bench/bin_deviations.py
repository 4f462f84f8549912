#!/usr/bin/python3
"""Each radial bin's particle count against the analytic ring, in binomial standard deviations
z = (n_b - N p_b) / sqrt(N p_b (1 - p_b)), p_b the bin's share of the analytic mass (bins expecting
fewer than 5 particles are left out): a run of same-signed z over several bins is a systematic
deficit or excess (the ring's tails: docs/validation.md, "The mixed gradient correction"), |z| ~ 1
scattered in sign is sampling noise. `sphdisk analyze` prints the annulus-mass L1 by region beside
its share of the floor; this shows the bins. Reads the JSON of `sphdisk analyze --json` (or
bench/ring_convergence.py's snapshot_NNN_analysis.json).

Usage: bench/bin_deviations.py ANALYSIS.json [...]
"""
import json
import math
import sys


def deviations(path):
    d = json.load(open(path))
    n, mass = d["particles"], d["initial_mass"]
    out = []
    for b in d["bins"]:
        p = b["sigma_ana_annulus"] * math.pi * (b["r_hi"] ** 2 - b["r_lo"] ** 2) / mass
        if n * p >= 5:
            out.append((0.5 * (b["r_lo"] + b["r_hi"]), (b["count"] - n * p) / math.sqrt(n * p * (1 - p))))
    return d, out


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for path in sys.argv[1:]:
        d, zs = deviations(path)
        print(f"{path}: N {d['particles']}, tau {d['tau']:.4g}; z by bin (r: z):")
        print("  " + " ".join(f"{r:.2f}:{z:+.1f}" for r, z in zs))


if __name__ == "__main__":
    main()
