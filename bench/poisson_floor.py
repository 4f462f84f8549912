#!/usr/bin/python3
"""Expected L1 error of the binned (annulus-mass) surface density from sampling noise alone.

Usage: poisson_floor.py ANALYSIS.json N [N ...]

With N equal-mass particles drawn at random from the exact profile, the count in bin b is binomial
(N, p_b) with p_b the bin's share of the mass; E|n_b - N p_b| ~ sqrt(2 N p_b (1 - p_b) / pi). The
L1 error that `sphdisk analyze` reports, sum_b |Sigma_b - Sigma_ana,b| / sum_b Sigma_ana,b, then has
this floor even for a perfect code: it is what random placement (P98 5.2) costs. The bins and the
analytic annulus means are read from an analysis written by `sphdisk analyze --json`.
"""
import json
import math
import sys


def main():
    a = json.load(open(sys.argv[1]))
    areas = [math.pi * (b["r_hi"] ** 2 - b["r_lo"] ** 2) for b in a["bins"]]
    mass = [b["sigma_ana_annulus"] * A for b, A in zip(a["bins"], areas)]
    total = sum(mass)
    den = sum(b["sigma_ana_annulus"] for b in a["bins"])
    for n in map(int, sys.argv[2:]):
        num = 0.0
        for m, A in zip(mass, areas):
            p = m / total
            num += math.sqrt(2 * n * p * (1 - p) / math.pi) * (total / n) / A
        print(f"N = {n}: expected L1 from sampling noise = {num / den:.4f}")


if __name__ == "__main__":
    main()
