#!/usr/bin/python3
"""Speedup and efficiency against threads (P98 Fig. 3) from force_bench CSV, with the symmetric
sequential variant (Fig. 4) marked as a horizontal reference.

Usage: plot_speedup.py speedup.csv speedup.png [summary.csv]
With several runs (column "run"), the median time of each (variant, threads, N) is plotted, and the
summary lists per N the median 2-thread efficiency and parallel/symmetric ratio with their ranges.
"""
import csv
import statistics
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main():
    rows = list(csv.DictReader(open(sys.argv[1])))
    times = defaultdict(list)  # (variant, N, threads) -> seconds of each run
    by_run = defaultdict(dict)  # (run, N) -> {(variant, threads): seconds}
    for r in rows:
        if r["variant"] not in ("parallel", "symmetric_sequential"):
            continue
        key = (r["variant"], int(r["particles"]), int(r["threads"]))
        times[key].append(float(r["seconds_per_evaluation"]))
        by_run[(r.get("run", "1"), key[1])][(key[0], key[2])] = float(r["seconds_per_evaluation"])
    par = defaultdict(dict)
    sym = {}
    for (variant, n, t), s in times.items():
        (par[n].__setitem__(t, statistics.median(s)) if variant == "parallel" else sym.__setitem__(n, statistics.median(s)))
    if len(sys.argv) > 3:
        with open(sys.argv[3], "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["particles", "runs", "efficiency_2_threads_median", "efficiency_min", "efficiency_max",
                        "parallel_over_symmetric_median", "ratio_min", "ratio_max"])
            for n in sorted(par):
                runs = [v for (run, m), v in by_run.items() if m == n]
                eff = [v[("parallel", 1)] / (2 * v[("parallel", 2)]) for v in runs if ("parallel", 2) in v]
                ratio = [v[("parallel", 1)] / v[("symmetric_sequential", 1)] for v in runs if ("symmetric_sequential", 1) in v]
                fmt = lambda xs, f: f"{f(xs):.3f}" if xs else ""
                w.writerow([n, len(runs), fmt(eff, statistics.median), fmt(eff, min), fmt(eff, max),
                            fmt(ratio, statistics.median), fmt(ratio, min), fmt(ratio, max)])
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9.6, 4.0), dpi=100)
    for n, seconds in sorted(par.items()):
        ts = sorted(seconds)
        speedup = [seconds[1] / seconds[t] for t in ts]
        ax1.plot(ts, speedup, "o-", label=f"N = {n:,}")
        ax2.plot(ts, [s / t for s, t in zip(speedup, ts)], "o-", label=f"N = {n:,}")
        if n in sym:
            ax1.axhline(seconds[1] / sym[n], ls=":", lw=0.8, color=ax1.lines[-1].get_color())
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
