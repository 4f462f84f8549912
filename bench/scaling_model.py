#!/usr/bin/python3
"""Strong-scaling model of sphdisk's distributed steps, from counted work and traffic.

The counters come from real runs (bench/scaling_counters.sh: per rank, over the steps alone, owned
particles, ghosts, pair interactions, and the bytes, messages and reductions each rank sent, by
purpose); the costs per unit from this machine (bench/comm_bench.cpp and 1-rank step times) or from
published figures. The model of one step on P ranks:

    t(P) = max_r C_r + max_r M_r

    C_r = c_pair * pairs_r + c_scan * cells                      compute (rank r's pairs; ghost choice)
    M_r = sum over purposes (migration, halo build, halo refresh, reductions) of
            E * (alpha * ceil(log2 P) + 8 P / B_R)               byte-count all-to-all of each exchange
          + m_r * alpha + b_r / B                                point-to-point messages and bytes
          + R * alpha * ceil(log2 P) + 2 * b_R / B_R             all-reduces (R calls, b_R bytes each rank)
          + G * (alpha * ceil(log2 P) + (P - 1) * b_G / B_R)     all-gathers (G calls of b_G bytes each rank)

Assumptions:
  * Ranks wait for each other at every exchange, so the slowest rank's compute and the busiest
    rank's communication add up (no overlap: the code has none). Imbalance enters through the max.
  * pairs_r = p_o * owned_r + p_g * ghosts_r (least squares over all measured ranks); the slowest
    rank has (N/P) * imbalance owned particles (measured up to 64 ranks, the rebalancing threshold
    1.05 beyond) and a mean rank's ghosts (the rank with the most ghosts has no more pairs than the
    others: its extra ghosts are spare).
  * A rank's exchange costs the larger of the bytes it sends and receives (its ghosts' bytes).
  * Ghosts per rank: min(c N^beta, A (N/P)^(1/2) + B), sectors across the ring on few ranks, 2D
    patches (ghosts ~ perimeter) on many (fit_ghosts), plus a constant for the busiest rank; bytes
    per ghost (whole particle at a halo build, the refreshed fields per step) as measured; migrated
    bytes in proportion to the mean ghosts (both cross a rank's boundary). Messages per exchange of
    the busiest rank: min(P - 1, the measured count at 64 ranks) (the 2M value for larger N).
  * Collectives as the code has them: each halo build gathers every rank's two boxes (BOX_BYTES per
    rank, domain/rank_boxes.hpp; all P boxes arrive on every rank) and sends its list of reading
    cells to the ranks within reach only (counted among the build's messages and bytes); the
    migration's send counts go by an all-to-all of one value per rank (an exchange's opening);
    the migration's check of the balance sums one count per rank (8 P bytes) and takes one maximum;
    the other all-reduces (the physics' selections, the build's few values) have sizes that do not
    grow with P. (A rebalance, when the counts drift past the threshold, sums one weight per top
    cell, O(P) bytes per rank: rare, and not in the step modelled here.) An all-reduce of n bytes costs ceil(log2 P) latencies and
    2 n / B_R (reduce-scatter and all-gather).
  * c_scan: each halo build walks the rank's own and listed top cells, ~(owned + ghosts) / 8 (8
    particles per top cell), an assumed 1 ns per cell. What still grows with P on every rank: the
    decomposition's owner of every top cell (4 bytes x 256 P), the gathered boxes (80 P bytes per
    build), each exchange's byte counts (8 P) and the balance check (8 P).
  * Machines: "here" (measured: c_pair from 1-rank CPU time per step; alpha, the exchange's B and
    the all-reduce's B from comm_bench over shared memory); Cray T3E-900 (one rank per node, alpha
    12.5 us, 300 MB/s per link, c_pair scaled by T3E_COMPUTE_FACTOR below); an InfiniBand cluster
    (128 ranks per node at this machine's alpha and all-reduce B inside, 200 Gb/s and 1.5 us between
    nodes, a node's off-node bytes 1 / sqrt(128) of its ranks' halo bytes, sharing the node's link;
    this machine's per-core speed).
  * Not modelled: output, set-up, the OS and network noise, contention inside the network, memory
    limits (the T3E's 128 MB per node holds ~80k particles of this code: runs below N / 80k nodes
    could not run there; speedups are relative to a 1-rank run all the same).

Usage: bench/scaling_model.py COUNTERS.csv COMM_BENCH.csv STEP_TIMES.csv CPU_TIMES.csv FIGURE.png
STEP_TIMES.csv: bench/mpi_scaling.sh's CSV (seconds_per_step: wall-time medians on 1 and 2 ranks);
CPU_TIMES.csv: bench/scaling_cpu_times.sh's. c_pair comes from the 1-rank CPU times (wall times
on a shared machine include other work's share of the cores); both 2-rank figures validate.
"""
import copy
import csv
import math
import sys
from collections import defaultdict

import numpy as np

PURPOSES = ("migration", "halo_build", "halo_refresh", "reductions")
COUNT_THRESHOLD = 1.05   # the rebalancing threshold: owned particles of the fullest rank / mean
C_SCAN = 1e-9            # seconds per top cell of the ghost choice's walk over its own and listed cells
BOX_BYTES = 80           # a rank's two boxes in 2D: 2 x (2 D + 1) doubles, gathered at each halo build
# The T3E-900's Alpha 21164 (450 MHz, 900 MFLOP/s peak) against one core here, on this memory-bound
# loop: ~90 MFLOP/s achieved (10% of peak, typical of gather/scatter codes on it) against the
# 3.0 GFLOP/s this code's force loop achieves here (docs/performance.md): a factor of ~30 (15-60
# for 5-20% of peak there).
T3E_COMPUTE_FACTOR = 30.0
P98_T3E = {100_000: (512, 183), 500_000: (512, 278)}  # P98 sec. 5.5: speedup on 512 nodes
MEASURED_N = (100_000, 500_000, 2_000_000)
MODEL_N = (100_000, 500_000, 2_000_000, 10_000_000, 100_000_000)
RANKS = [2**k for k in range(13)]


def read_counters(path):
    """Per run (N, P): the per-rank rows, every count per step."""
    runs = defaultdict(list)
    for row in csv.DictReader(open(path)):
        r = {k: float(v) for k, v in row.items()}
        steps = r["steps"]
        migrations = max(steps - 1, 1)  # the first step of a run does not rebalance
        for k in list(r):
            if k.startswith("migration_"):
                r[k] /= migrations
            elif k.split("_")[0] in ("halo", "reductions", "pair", "particle", "h", "rate"):
                r[k] /= steps
        runs[(int(r["particles"]), int(r["ranks"]))].append(r)
    return runs


def fit_counters(runs):
    """The extrapolation's constants, fitted to the measured runs on 2 or more ranks."""
    rows = [r for (n, p), rs in runs.items() if p > 1 for r in rs]
    owned = np.array([r["owned"] for r in rows])
    ghosts = np.array([r["ghosts"] for r in rows])
    pairs = np.array([r["pair_interactions"] for r in rows])
    (p_o, p_g), *_ = np.linalg.lstsq(np.c_[owned, ghosts], pairs, rcond=None)
    multi = {k: v for k, v in runs.items() if k[1] > 1}
    root = np.array([math.sqrt(n / p) for (n, p) in multi])
    g_mean = np.array([np.mean([r["ghosts"] for r in rs]) for rs in multi.values()])
    sum_ghosts = sum(r["ghosts"] for r in rows)
    f = dict(p_o=p_o, p_g=p_g, **fit_ghosts(multi),
             exponent=float(np.polyfit(np.log(root**2), np.log(g_mean), 1)[0]),
             build_bytes_per_ghost=sum(r["halo_build_bytes"] for r in rows) / sum_ghosts,
             refresh_bytes_per_ghost=sum(r["halo_refresh_bytes"] for r in rows) / sum_ghosts,
             builds=np.mean([r["halo_build_exchanges"] for r in rows]),
             refreshes=np.mean([r["halo_refresh_exchanges"] for r in rows]),
             migration_exchanges=np.mean([r["migration_exchanges"] for r in rows]))
    # Particles leaving a rank cross its boundary, like its ghosts: bytes ~ mean ghosts.
    mig = np.array([max(r["migration_bytes"] for r in rs) for rs in multi.values()])
    f["k_migration"] = float(g_mean @ mig / (g_mean @ g_mean))
    # Each halo build is two exchanges (cell lists, then ghosts) and one gather of the boxes; its
    # other all-reduces and the migration's carry a few values each.
    f["gathers"] = f["builds"] / 2
    f["halo_reductions"] = np.mean([r["halo_build_reductions"] for r in rows]) - f["gathers"]
    f["halo_reduction_bytes"] = np.mean([r["halo_build_reduction_bytes"] for r in rows]) - f["gathers"] * BOX_BYTES
    f["phys_reductions"] = np.mean([r["reductions_reductions"] for r in rows])
    f["phys_reduction_bytes"] = np.mean([r["reductions_reduction_bytes"] for r in rows])
    f["migration_reductions"] = np.mean([r["migration_reductions"] for r in rows])
    f["messages_at_64"] = {n: max(max(r["halo_build_messages"] for r in runs[(n, 64)]) / f["builds"],
                                  max(r["halo_refresh_messages"] for r in runs[(n, 64)]) / f["refreshes"])
                           for n in MEASURED_N if (n, 64) in runs}
    return f


def fit_ghosts(multi):
    """Mean ghosts per rank: min(c N^beta, A (N/P)^1/2 + B). On few ranks each domain is a sector
    across the whole ring, whose cut edges do not shorten as P grows (c N^beta, fitted on 2 to 8
    ranks); on many, domains are 2D patches and the halo is their perimeter, A (N/P)^1/2 (fitted on
    32 and 64 ranks; B: the corners and spare ghosts of whole halo cells). The busiest rank has
    `extra` more (the rank of the ring's sparse centre or rim, whose wide smoothing lengths reach
    many cells): max - mean at the largest N and P measured."""
    mean = {k: np.mean([r["ghosts"] for r in rs]) for k, rs in multi.items()}
    ring = [(math.log(n), math.log(g)) for (n, p), g in mean.items() if p <= 8]
    beta, log_c = np.polyfit(*zip(*ring), 1)
    patch = [(math.sqrt(n / p), g) for (n, p), g in mean.items() if p >= 32]
    A, B = np.polyfit(*zip(*patch), 1)
    n, p = max(multi, key=lambda k: (k[1], k[0]))
    g = [r["ghosts"] for r in multi[(n, p)]]
    return dict(c_ring=math.exp(log_c), beta=beta, A=A, B=B, extra=max(g) - np.mean(g))


def mean_ghosts(n, p, f):
    return min(f["c_ring"] * n ** f["beta"], f["A"] * math.sqrt(n / p) + f["B"])


def halo_volume_estimate(owned, neighbours=60, margin=1.25, cell_particles=8):
    """Ghosts of a square domain of `owned` particles at spacing d: its perimeter times a halo of
    width w = margin 2h plus half a halo top cell, 2h = d (neighbours / pi)^1/2."""
    w = margin * math.sqrt(neighbours / math.pi) + 0.5 * math.sqrt(cell_particles)
    return 4 * math.sqrt(owned) * w + math.pi * w * w


def halo_cells(owned, ghosts):
    """Top cells a halo build walks: the rank's own and the listed ones, 8 particles per cell."""
    return (owned + ghosts) / 8


def count_imbalance(p, runs):
    """Owned particles of the fullest rank / mean: as measured at the largest N on P ranks, and the
    rebalancing threshold beyond (long runs drift up to it before the domains are cut anew)."""
    measured = [(n, rs) for (n, q), rs in runs.items() if q == p]
    if not measured:
        return COUNT_THRESHOLD
    return max(measured, key=lambda x: x[0])[1][0]["count_imbalance"]


def step_counts(n, p, f, runs, use_measured=True):
    """The busiest rank's counts per step: measured where the run exists, else extrapolated."""
    if use_measured and (n, p) in runs:
        rs = runs[(n, p)]
        mx = lambda k: max(r[k] for r in rs)
        c = dict(measured=True, pairs=mx("pair_interactions"), ghosts=mx("ghosts"),
                 cells=halo_cells(mx("owned"), mx("ghosts")))
        for q in PURPOSES:
            c[q] = dict(exchanges=rs[0][f"{q}_exchanges"], messages=mx(f"{q}_messages"), bytes=mx(f"{q}_bytes"),
                        reductions=rs[0][f"{q}_reductions"], reduction_bytes=rs[0][f"{q}_reduction_bytes"],
                        gathers=0, gather_bytes=0)
        # The build's gathers are counted among its reductions.
        h = c["halo_build"]
        h.update(gathers=f["gathers"], gather_bytes=BOX_BYTES, reductions=h["reductions"] - f["gathers"],
                 reduction_bytes=h["reduction_bytes"] - f["gathers"] * BOX_BYTES)
        # A rank's exchange costs what it sends or what it receives, whichever is more; the counters
        # hold what each rank sent, its ghosts what it received.
        c["halo_build"]["bytes"] = max(c["halo_build"]["bytes"], f["build_bytes_per_ghost"] * c["ghosts"])
        c["halo_refresh"]["bytes"] = max(c["halo_refresh"]["bytes"], f["refresh_bytes_per_ghost"] * c["ghosts"])
        return c
    if p == 1:
        return dict(measured=False, pairs=f["p_o"] * n, ghosts=0, cells=0,
                    **{q: dict(exchanges=0, messages=0, bytes=0, reductions=0, reduction_bytes=0, gathers=0,
                               gather_bytes=0) for q in PURPOSES})
    g_max = mean_ghosts(n, p, f) + f["extra"]
    m64 = f["messages_at_64"].get(n, f["messages_at_64"][max(f["messages_at_64"])])
    msgs = min(p - 1, m64)
    # The busiest rank's extra ghosts are spare ones (measured: no more pairs than the others).
    c = dict(measured=False, pairs=f["p_o"] * n / p * count_imbalance(p, runs) + f["p_g"] * mean_ghosts(n, p, f),
             ghosts=g_max, cells=halo_cells(n / p * count_imbalance(p, runs), g_max))
    none = dict(gathers=0, gather_bytes=0)
    c["halo_build"] = dict(exchanges=f["builds"], messages=msgs * f["builds"],
                           bytes=f["build_bytes_per_ghost"] * g_max, reductions=f["halo_reductions"],
                           reduction_bytes=f["halo_reduction_bytes"], gathers=f["gathers"], gather_bytes=BOX_BYTES)
    c["halo_refresh"] = dict(exchanges=f["refreshes"], messages=msgs * f["refreshes"],
                             bytes=f["refresh_bytes_per_ghost"] * g_max, reductions=0, reduction_bytes=0, **none)
    c["migration"] = dict(exchanges=f["migration_exchanges"], messages=msgs, bytes=f["k_migration"] * mean_ghosts(n, p, f),
                          reductions=f["migration_reductions"], reduction_bytes=8.0 * (p + 1), **none)
    c["reductions"] = dict(exchanges=0, messages=0, bytes=0, reductions=f["phys_reductions"],
                           reduction_bytes=f["phys_reduction_bytes"], **none)
    return c


class Machine:
    """Costs per unit: c_pair (s per pair interaction), and per message / byte / all-reduce on P ranks."""

    def __init__(self, name, c_pair, alpha, bandwidth, reduce_bandwidth, ranks_per_node=1, net_alpha=None,
                 net_bandwidth=None):
        self.name, self.c_pair, self.alpha, self.bandwidth = name, c_pair, alpha, bandwidth
        self.reduce_bandwidth = reduce_bandwidth
        self.rpn, self.net_alpha, self.net_bandwidth = ranks_per_node, net_alpha, net_bandwidth

    def off_node(self, p):
        """Share of a rank's halo bytes that leave its node (0 on one node)."""
        return 0.0 if self.net_alpha is None or p <= self.rpn else 1.0 / math.sqrt(self.rpn)

    def point_to_point(self, messages, nbytes, p):
        off = self.off_node(p)
        if off == 0:
            return messages * self.alpha + nbytes / self.bandwidth
        inside = messages * (1 - off) * self.alpha + nbytes * (1 - off) / self.bandwidth
        # The node's ranks share its link: their off-node bytes leave one after another.
        return inside + messages * off * self.net_alpha + nbytes * off * self.rpn / self.net_bandwidth

    def all_reduce(self, calls, nbytes, p):
        lat = math.ceil(math.log2(p)) if p > 1 else 0
        if self.net_alpha is None or p <= self.rpn:
            return calls * lat * self.alpha + 2 * nbytes / self.reduce_bandwidth
        nodes = math.ceil(p / self.rpn)
        inside = calls * math.ceil(math.log2(self.rpn)) * self.alpha + 2 * nbytes / self.reduce_bandwidth
        return inside + calls * math.ceil(math.log2(nodes)) * self.net_alpha + 2 * nbytes / self.net_bandwidth

    def all_gather(self, calls, nbytes, p):
        """Each rank receives (P - 1) n bytes: an all-reduce's cost with 2 n replaced by that."""
        return self.all_reduce(calls, (p - 1) * nbytes / 2, p)

    def step(self, c, p):
        """Seconds per step and its parts for the busiest rank's counts c."""
        parts = dict(compute=self.c_pair * c["pairs"], scan=C_SCAN * c["cells"] * (p > 1),
                     latency=0.0, bandwidth=0.0, reduction=0.0)
        lat = math.ceil(math.log2(p)) if p > 1 else 0
        for q in PURPOSES:
            t = c[q]
            alpha = self.alpha if self.off_node(p) == 0 else self.net_alpha
            parts["latency"] += t["exchanges"] * lat * alpha
            parts["bandwidth"] += t["exchanges"] * 8 * p / self.reduce_bandwidth * (p > 1)  # the byte counts
            pp = self.point_to_point(t["messages"], t["bytes"], p)
            parts["latency"] += self.point_to_point(t["messages"], 0, p)
            parts["bandwidth"] += pp - self.point_to_point(t["messages"], 0, p)
            parts["reduction"] += self.all_reduce(t["reductions"], t["reduction_bytes"], p)
            parts["reduction"] += self.all_gather(t["gathers"], t["gather_bytes"], p)
        return sum(parts.values()), parts


def comm_constants(path):
    """alpha, B and the all-reduce's B from comm_bench rows on 2 ranks, the fastest repeat of each
    size (this machine is shared: slower repeats met other work). An exchange on 2 ranks is two
    latencies (the counts all-to-all, then the data); its B is the slope over 256 KiB and more; the
    all-reduce's from its largest size, t = 2 n / B."""
    best = defaultdict(lambda: math.inf)
    for r in csv.DictReader(open(path)):
        if int(r["ranks"]) == 2:
            key = (r["operation"], int(r["bytes"]))
            best[key] = min(best[key], float(r["seconds"]))
    alpha = min(t for (op, b), t in best.items() if op == "exchange" and b <= 4096) / 2
    large = sorted((b, t) for (op, b), t in best.items() if op == "exchange" and b >= 1 << 18)
    per_byte = np.polyfit(*zip(*large), 1)[0]
    b_red, t_red = max((b, t) for (op, b), t in best.items() if op == "all_reduce")
    return alpha, 1 / per_byte, 2 * b_red / t_red


def cpu_per_step(path):
    """CPU seconds per step of each rank, by (N, P): (12-step run - 2-step run) / 10, per repeat."""
    t = {}
    for r in csv.DictReader(open(path)):
        t[(int(r["particles"]), int(r["ranks"]), int(r["repeat"]), int(r["rank"]), int(r["steps"]))] = \
            float(r["user_s"]) + float(r["sys_s"])
    out = defaultdict(list)  # (N, P) -> per repeat, the busiest rank's
    for (n, p, rep, rank, steps), v in t.items():
        if steps == 12 and rank == 0:
            out[(n, p)].append(max((t[(n, p, rep, k, 12)] - t[(n, p, rep, k, 2)]) / 10 for k in range(p)))
    return out


def main(counters_csv, comm_csv, steps_csv, cpu_csv, figure):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    runs = read_counters(counters_csv)
    f = fit_counters(runs)
    times = defaultdict(list)
    for r in csv.DictReader(open(steps_csv)):
        times[(int(r["particles"]), int(r["ranks"]))].append(float(r["seconds_per_step"]))
    cpu = cpu_per_step(cpu_csv)
    c_pair = float(np.mean([np.median(ts) / runs[(n, 1)][0]["pair_interactions"] for (n, p), ts in cpu.items()
                            if p == 1]))
    wall_c_pair = float(np.mean([min(ts) / runs[(n, 1)][0]["pair_interactions"] for (n, p), ts in times.items()
                                 if p == 1]))
    alpha, bandwidth, reduce_bandwidth = comm_constants(comm_csv)
    here = Machine("this machine", c_pair, alpha, bandwidth, reduce_bandwidth)
    machines = [Machine(f"Cray T3E-900 (compute x{T3E_COMPUTE_FACTOR:g} slower per pair)",
                        c_pair * T3E_COMPUTE_FACTOR, 12.5e-6, 300e6, 300e6),
                Machine("InfiniBand cluster (128 ranks/node, 200 Gb/s, 1.5 us)", c_pair, alpha, reduce_bandwidth,
                        reduce_bandwidth, ranks_per_node=128, net_alpha=1.5e-6, net_bandwidth=25e9)]
    # What the choices nobody measured move: the T3E's compute factor, the node's copy rate.
    variants = [Machine(f"T3E-900, compute x{k:g}", c_pair * k, 12.5e-6, 300e6, 300e6) for k in (15, 60)]
    variants.append(Machine("InfiniBand, intra-node at the exchange's rate here", c_pair, alpha, bandwidth,
                            reduce_bandwidth, ranks_per_node=128, net_alpha=1.5e-6, net_bandwidth=25e9))

    print(f"c_pair here {c_pair:.3e} s CPU per pair interaction ({1 / c_pair:.3g} pairs/s; "
          f"{wall_c_pair:.3e} s of wall time on the shared machine); "
          f"alpha {alpha * 1e6:.2f} us, B {bandwidth / 1e9:.2f} GB/s (exchange), {reduce_bandwidth / 1e9:.2f} GB/s "
          f"(all-reduce), shared-memory MPI")
    print(f"fits: pairs = {f['p_o']:.2f} owned + {f['p_g']:.2f} ghosts; ghosts/rank mean min({f['c_ring']:.2f} "
          f"N^{f['beta']:.2f}, {f['A']:.1f} (N/P)^1/2 + {f['B']:.0f}), busiest rank +{f['extra']:.0f} (one power "
          f"law of the mean in N/P would have exponent {f['exponent']:.2f}); migration {f['k_migration']:.1f} B per "
          f"mean ghost; "
          f"{f['build_bytes_per_ghost']:.0f} B per ghost per build, {f['refresh_bytes_per_ghost']:.0f} per step "
          f"refreshed; per build {f['gathers']:.2f} gathers of {BOX_BYTES} B and {f['halo_reductions']:.2f} all-reduces "
          f"of {f['halo_reduction_bytes']:.0f} B; messages at 64 ranks {f['messages_at_64']}")

    print("\nvalidation on this machine (s/step): particles, ranks, model, measured wall (median), busiest "
          "rank's CPU (median), model / CPU")
    for (n, p), ts in sorted(times.items()):
        t, parts = here.step(step_counts(n, p, f, runs), p)
        c = float(np.median(cpu[(n, p)])) if (n, p) in cpu else math.nan
        print(f"  {n:>9,} {p:>3} {t:.4f} {min(ts):.4f} {c:.4f} {t / c:.2f}  "
              + " ".join(f"{k} {v:.4f}" for k, v in parts.items()))
    print("\nghosts per rank, measured mean (max) against the fit (+extra), and the halo-volume estimate "
          "of a square domain (4 (N/P)^1/2 w/d + pi (w/d)^2):")
    for (n, p), rs in sorted(runs.items()):
        if p > 1:
            g = [r["ghosts"] for r in rs]
            fit = mean_ghosts(n, p, f)
            print(f"  {n:>9,} {p:>3}: {np.mean(g):8.0f} ({max(g):6.0f})  fit {fit:8.0f} ({fit + f['extra']:6.0f})"
                  f"  square {halo_volume_estimate(n / p):8.0f}")

    print("\nthe extrapolation's formulas against the measured counters per step, busiest rank (formula / measured):")
    for n in MEASURED_N:
        for p in (8, 64):
            a, b = step_counts(n, p, f, runs, False), step_counts(n, p, f, runs)
            ratio = lambda q, k: a[q][k] / b[q][k] if b[q][k] else math.nan
            print(f"  {n:>9,} {p:>3}: pairs {a['pairs'] / b['pairs']:.2f}, ghosts {a['ghosts'] / b['ghosts']:.2f}, "
                  f"halo bytes {ratio('halo_build', 'bytes'):.2f} + {ratio('halo_refresh', 'bytes'):.2f}, "
                  f"messages {ratio('halo_build', 'messages'):.2f}, migration bytes {ratio('migration', 'bytes'):.2f}, "
                  f"all-reduce bytes {ratio('halo_build', 'reduction_bytes'):.2f} + "
                  f"{ratio('migration', 'reduction_bytes'):.2f} + {ratio('reductions', 'reduction_bytes'):.2f}")
    fig, axes = plt.subplots(2, 2, figsize=(11, 8.5))
    for col, m in enumerate(machines):
        print(f"\n{m.name}:")
        colours = {}
        for n in MODEL_N:
            t1, below, eff, spd, meas = scan_ranks(m, n, f, runs)
            colours[n] = plot_curves(axes[0][col], axes[1][col], n, spd, eff, meas)
            print(half_efficiency_line(n, t1, below, eff))
        if col == 0:
            for n, (p, s) in P98_T3E.items():
                style = dict(marker="*", ms=14, color=colours[n], markeredgecolor="k", ls="none")
                axes[0][0].plot(p, s, label=f"P98 Fig. 9, {n // 1000}k: {s} on {p} (sec. 5.5)", **style)
                axes[1][0].plot(p, s / p, **style)
        axes[0][col].set_title(m.name, fontsize=9)
    for k in (T3E_COMPUTE_FACTOR, 60.0):
        t3e = Machine("T3E", c_pair * k, 12.5e-6, 300e6, 300e6)
        print(f"\nT3E-900 (x{k:g}) at P98's points: " + "; ".join(
            f"{n // 1000}k on {p}: speedup {t3e_speedup(t3e, n, p, f, runs):.0f} (P98 {s})" for n, (p, s) in P98_T3E.items()))
    for m in variants:
        print(f"\nsensitivity, {m.name}:")
        for n in MODEL_N:
            print(half_efficiency_line(n, *scan_ranks(m, n, f, runs)[:3]))
    m = machines[1]
    print(f"\nhybrid ranks x threads on {m.name}: efficiency on 1024 / 4096 cores with 1, 8, 32 threads per rank:")
    for n in MODEL_N:
        print(f"  N={n:>11,}: " + "; ".join(
            f"{hybrid_efficiency(m, n, 1024, t, f, runs):.0%} / {hybrid_efficiency(m, n, 4096, t, f, runs):.0%}"
            for t in (1, 8, 32)))
    for ax in axes.flat:
        ax.set_xscale("log", base=2)
        ax.set_xlabel("ranks")
        ax.grid(alpha=0.3)
    for ax in axes[0]:
        ax.set_yscale("log", base=2)
        ax.plot(RANKS, RANKS, "k:", lw=0.8)
        ax.set_ylabel("speedup")
        ax.legend(fontsize=7)
    for ax in axes[1]:
        ax.set_ylim(0, 1.05)
        ax.set_ylabel("efficiency")
    fig.suptitle("Modelled strong scaling of the ring step (solid: measured counters, dashed: extrapolated)",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(figure, dpi=110)
    print(f"\nfigure -> {figure}")


def scan_ranks(m, n, f, runs):
    """One-rank time, the first (P, t, parts) below 50% efficiency, and per P: efficiency, speedup,
    whether the counters were measured."""
    t1 = m.step(step_counts(n, 1, f, runs), 1)[0]
    eff, spd, meas, below = [], [], [], None
    for p in RANKS:
        c = step_counts(n, p, f, runs)
        t, parts = m.step(c, p)
        spd.append(t1 / t)
        eff.append(t1 / t / p)
        meas.append(c["measured"])
        if below is None and eff[-1] < 0.5:
            below = (p, t, parts)
    return t1, below, eff, spd, meas


def t3e_speedup(m, n, p, f, runs):
    return m.step(step_counts(n, 1, f, runs), 1)[0] / m.step(step_counts(n, p, f, runs), p)[0]


def hybrid_efficiency(m, n, cores, threads, f, runs, thread_efficiency=0.85):
    """Efficiency on `cores` cores as cores / threads ranks of `threads` threads each (the rank's
    compute divided among its threads at thread_efficiency, its communication unchanged; a node
    holds 1 / threads as many ranks)."""
    t1 = m.step(step_counts(n, 1, f, runs), 1)[0]
    p = max(cores // threads, 1)
    m = copy.copy(m)
    m.rpn = max(m.rpn // threads, 1)
    t, parts = m.step(step_counts(n, p, f, runs), p)
    t -= parts["compute"] * (1 - 1 / (threads * (thread_efficiency if threads > 1 else 1.0)))
    return t1 / t / cores


def half_efficiency_line(n, t1, below, eff):
    """Where efficiency falls below 50%, and the losses there (shares of the step, largest first)."""
    if not below:
        return f"  N={n:>11,}: efficiency {eff[-1]:.0%} at {RANKS[-1]} ranks"
    p, t, parts = below
    why = dict(imbalance_and_ghosts=parts["compute"] - t1 / p, halo_scan=parts["scan"], latency=parts["latency"],
               bandwidth=parts["bandwidth"], reductions=parts["reduction"])
    top = sorted(why.items(), key=lambda kv: -kv[1])
    return (f"  N={n:>11,}: efficiency below 50% from {p} ranks; of its {t * 1e3:.3g} ms step, "
            + ", ".join(f"{k} {v / t:.0%}" for k, v in top))


def plot_curves(ax_s, ax_e, n, spd, eff, meas):
    """Solid where the counters were measured, dashed where extrapolated."""
    label = f"{n / 1e6:g}M" if n >= 1_000_000 else f"{n // 1000}k"
    last = max([i for i, m in enumerate(meas) if m] + [0])
    (line,) = ax_s.plot(RANKS[: last + 1], spd[: last + 1], "-", lw=1.8, label=label)
    colour = line.get_color()
    ax_s.plot(RANKS[last:], spd[last:], "--", color=colour, lw=1.8)
    ax_e.plot(RANKS[: last + 1], eff[: last + 1], "-", color=colour, lw=1.8)
    ax_e.plot(RANKS[last:], eff[last:], "--", color=colour, lw=1.8)
    return colour


if __name__ == "__main__":
    main(*sys.argv[1:6])
