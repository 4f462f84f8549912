#!/usr/bin/python3
"""Speedup and efficiency against threads (P98 Fig. 3) from force_bench CSV, with the symmetric
sequential variant (Fig. 4) marked as a horizontal reference.

Usage: plot_speedup.py speedup.csv speedup.png
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main():
    rows = list(csv.DictReader(open(sys.argv[1])))
    par = defaultdict(dict)
    sym = {}
    for r in rows:
        n, t, s = int(r["particles"]), int(r["threads"]), float(r["seconds_per_evaluation"])
        (par[n].__setitem__(t, s) if r["variant"] == "parallel" else sym.__setitem__(n, s))
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9.6, 4.0), dpi=100)
    for n, times in sorted(par.items()):
        ts = sorted(times)
        speedup = [times[1] / times[t] for t in ts]
        ax1.plot(ts, speedup, "o-", label=f"N = {n:,}")
        ax2.plot(ts, [s / t for s, t in zip(speedup, ts)], "o-", label=f"N = {n:,}")
        if n in sym:
            ax1.axhline(times[1] / sym[n], ls=":", lw=0.8, color=ax1.lines[-1].get_color())
    top = max(max(t) for t in par.values())
    ax1.plot([1, top], [1, top], "k--", lw=0.8, label="ideal")
    ax1.set(xlabel="threads", ylabel="speedup T(1)/T(p)", title="speedup (dotted: symmetric sequential)")
    ax2.set(xlabel="threads", ylabel="efficiency", ylim=(0, 1.1), title="parallel efficiency")
    ax1.legend(fontsize=8)
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(sys.argv[2])


if __name__ == "__main__":
    main()
