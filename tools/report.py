#!/usr/bin/python3
"""Draw the figures of a sphdisk run and write a Markdown report.

    report.py DIR [--out DIR/report]

DIR holds snapshot_000.hdf5, snapshot_001.hdf5, ... (layout: docs/formats.md, "Snapshot files"),
optionally diagnostics.csv, timers.json, ranks.json and scaling.csv. report.md opens with a summary
(what ran, the ring's verdict figures, conservation), then the figures (PNG at 300 dpi and PDF, journal
column widths), then the details. Ring runs (ring_model.is_ring_run) are compared with the analytic
ring, P98 eqs. 11-12 in code units (G = M = 1), following the paper's sec. 5 (Figs. 3, 5-10); any other
disc gets radial profiles without analytic curves (disc_profiles.py). Every disc run gets column-density
maps of its outputs (report_images.py) and profiles.csv. A blast wave (Header Problem "sedov") gets
its profiles against the Sedov-Taylor solution instead (sedov_report.py).
Exit status: 0 on success, 2 when DIR is missing or holds no snapshots, 1 on any other error
(always with a one-line message on stderr).
"""
import argparse
import math
import os
import sys
from dataclasses import dataclass

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.dont_write_bytecode = True  # no tools/__pycache__ in the source tree
from analyze_json import analysis  # noqa: E402
from disc_profiles import (PROFILES_CSV, data_edges, plot_accreted_mass, plot_profiles,  # noqa: E402
                           radial_profile, write_profiles_csv)
from report_figures import (plot_binned_sigma, plot_conservation, plot_error, plot_positions,  # noqa: E402
                            plot_scaling_curves, plot_sigma, plot_vr, short_label, snapshot_note)
from report_images import common_norm, plot_column_density, render_column_density, sigma_unit  # noqa: E402
from report_text import write_markdown  # noqa: E402
from ring_model import (BIN_RANGE, N_BINS, SCATTER_CUT, Ring, annulus_mean_analytic, fit_tau,  # noqa: E402
                        l1_against, ring_from_header, sampling_floor, snapshot_tau)
from run_data import (SNAPSHOT_RE, UsageError, load_run, read_csv_columns, read_particles,  # noqa: E402
                      survey)
from sedov_report import is_sedov_run, write_report as write_sedov_report  # noqa: E402

TAU_FIGURES = 0.09            # ring snapshot shown in Figs. 5-7 (paper: tau = 0.09)

FIG_POSITIONS = "fig5_positions.png"
FIG_SIGMA = "fig6_sigma.png"
FIG_VR = "fig7_vr.png"
FIG_BINNED = "fig8_binned_sigma.png"
FIG_ERROR = "error_vs_time.png"
FIG_CONSERVATION = "conservation.png"
FIG_ACCRETED = "accreted_mass.png"
FIG_PROFILES = "disc_profiles.png"
FIG_MAP = "sigma_map_{}.png"  # snapshot number of the file name
FIG_SPEEDUP = "fig9_speedup.png"
FIG_EFFICIENCY = "fig9_efficiency.png"
FIG_COMM = "fig10_comm_time.png"


# ----------------------------------------------------------------------------- analysis

@dataclass
class SnapshotStats:
    name: str
    time: float
    tau: float | None
    particles: int
    ring: Ring | None
    centres: np.ndarray
    mean_sph: np.ndarray
    mean_ana: np.ndarray | None
    counts: np.ndarray
    l1: float | None
    scatter: float | None
    mass_sigma: np.ndarray          # annulus mass / annulus area
    mass_ana: np.ndarray | None     # analytic annulus mean of Sigma
    l1_mass: float | None
    mean_noself: np.ndarray | None  # particle mean of the self-term-free summation density
    mass: float = math.nan
    accreted: float | None = None   # Header AccretedMass
    floor: float | None = None      # sampling floor of the annulus-mass L1
    tau_fit: float | None = None    # best-fit viscous time tau*
    l1_at_fit: float | None = None

    @property
    def rate(self):
        return self.tau_fit / self.tau if self.tau_fit and self.tau else None


def ring_edges(r0):
    return r0 * np.linspace(BIN_RANGE[0], BIN_RANGE[1], N_BINS + 1)


def binned_mean(r, values, edges):
    """Mean of values per radial bin (NaN where a bin is empty) and the counts."""
    counts, _ = np.histogram(r, bins=edges)
    sums, _ = np.histogram(r, bins=edges, weights=values)
    with np.errstate(invalid="ignore", divide="ignore"):
        return sums / counts, counts


def l1_error(mean_sph, mean_ana, counts):
    """sum |<Sigma_sph> - <Sigma_ana>| / sum <Sigma_ana> over non-empty bins."""
    used = (counts > 0) & np.isfinite(mean_sph) & np.isfinite(mean_ana)
    denom = np.sum(mean_ana[used])
    return float(np.sum(np.abs(mean_sph[used] - mean_ana[used])) / denom) if denom > 0 else None


def annulus_sigma(r, mass, edges):
    """Surface density from the particle mass in each annulus divided by its area."""
    m, _ = np.histogram(r, bins=edges, weights=mass)
    return m / (np.pi * (edges[1:] ** 2 - edges[:-1] ** 2))


def particle_scatter(sigma, sigma_ana, peak):
    """std of Sigma_sph / Sigma_ana - 1 over particles with Sigma_ana > SCATTER_CUT * peak."""
    used = np.isfinite(sigma) & np.isfinite(sigma_ana) & (sigma_ana > SCATTER_CUT * peak)
    return float(np.std(sigma[used] / sigma_ana[used] - 1.0)) if used.sum() > 1 else None


def ring_measures(stats, parts, edges):
    """Fills in the comparison of a ring snapshot with the analytic ring (docs/physics.md sec. 4)."""
    ring = stats.ring
    sigma_ana = ring.sigma(parts["r"])
    stats.mean_ana, _ = binned_mean(parts["r"], sigma_ana, edges)
    stats.l1 = l1_error(stats.mean_sph, stats.mean_ana, stats.counts)
    stats.scatter = particle_scatter(parts["sigma"], sigma_ana, ring.peak_sigma())
    stats.mass_ana = annulus_mean_analytic(ring, edges)
    stats.l1_mass = l1_against(stats.mass_sigma, stats.mass_ana)
    stats.floor = sampling_floor(ring, edges, stats.particles)
    stats.tau_fit, stats.l1_at_fit = fit_tau(ring, edges, stats.mass_sigma)


def snapshot_stats(path, header, parts, edges, ring_run):
    """Binned Sigma of a snapshot and, for a ring run, its comparison with the analytic ring."""
    mean_sph, counts = binned_mean(parts["r"], parts["sigma"], edges)
    noself = parts.get("sigma_noself")
    stats = SnapshotStats(os.path.basename(path), float(header.get("Time", math.nan)), snapshot_tau(header),
                          len(parts["r"]), ring_from_header(header) if ring_run else None,
                          0.5 * (edges[1:] + edges[:-1]), mean_sph, None, counts, None, None,
                          annulus_sigma(parts["r"], parts["mass"], edges), None, None,
                          binned_mean(parts["r"], noself, edges)[0] if noself is not None else None,
                          mass=float(np.sum(parts["mass"])), accreted=header.get("AccretedMass"))
    if stats.ring:
        ring_measures(stats, parts, edges)
    return stats


def pick_figure_snapshot(headers, ring_run=True):
    """Index of the ring snapshot nearest tau = TAU_FIGURES; the last one otherwise."""
    taus = [snapshot_tau(h) for h in headers]
    if not ring_run or any(t is None for t in taus):
        return len(headers) - 1
    return int(np.argmin([abs(t - TAU_FIGURES) for t in taus]))


def speedup_table(scaling):
    """Per particle number: workers, speedup T(p_min) p_min / T(p), efficiency, comm time (sorted)."""
    table = {}
    for n in np.unique(scaling["particles"][np.isfinite(scaling["particles"])]):
        sel = scaling["particles"] == n
        order = np.argsort(scaling["workers"][sel])
        p = scaling["workers"][sel][order]
        t = scaling["wall_time"][sel][order]
        speedup = p[0] * t[0] / t
        comm = scaling["comm_time"][sel][order] if "comm_time" in scaling else None
        table[int(n)] = {"workers": p, "speedup": speedup, "efficiency": speedup / p, "comm": comm}
    return table


# ----------------------------------------------------------------------------- driver

def snapshot_number(path):
    return SNAPSHOT_RE.match(os.path.basename(path)).group(1)


def where(stats):
    """Snapshot name and its viscous time (ring runs) or time, for captions."""
    return f"{stats.name}, {short_label(stats)}"


def draw_chosen_snapshot(run, parts, stats, profile, out_dir):
    """Figs. 5-7 of one snapshot."""
    plot_positions(parts, stats, run.r0, os.path.join(out_dir, FIG_POSITIONS))
    plot_sigma(parts, stats, run.r0, os.path.join(out_dir, FIG_SIGMA))
    plot_vr(parts, stats, profile, run.r0, os.path.join(out_dir, FIG_VR))
    analytic = " and the analytic ring (line)" if stats.ring else ""
    run.figures += [(f"Fig. 5: particle positions ({where(stats)})", FIG_POSITIONS),
                    (f"Fig. 6: particle Σ against radius{analytic} ({where(stats)})", FIG_SIGMA),
                    (f"Fig. 7: radial velocity ({where(stats)}): left the particles' own v_r, with their epicycles, "
                     "right the guiding-centre drift; circles: mass-weighted bin means"
                     + ("; line: analytic ring" if stats.ring else ""), FIG_VR)]
    if parts["drift"] is None:
        run.notes.append(f"{stats.name} has no Acceleration dataset: no guiding-centre drift.")
    if parts.get("column"):
        run.notes.append("3D run: the particle Σ of Figs. 6 and 8 is each particle's column density seen from above "
                         "(2D cubic spline, the particles' own h); Density in the snapshots is a volume density.")


def draw_maps(run, images, half_width, out_dir):
    """One column-density map per output, all on the same frame and colour scale."""
    factor, label = sigma_unit(run.units)
    norm = common_norm([im * factor for im, _, _ in images])
    for image, stats, path in images:
        name = FIG_MAP.format(snapshot_number(path))
        plot_column_density(image * factor, half_width, norm, label, snapshot_note(stats),
                            os.path.join(out_dir, name))
        run.figures.append((f"Column density Σ ({where(stats)}): SPH sum with the cubic spline kernel and the "
                            "particles' own h, log scale", name))


def draw_snapshot_figures(run, out_dir):
    """Per-snapshot analysis, Figs. 5-8, the maps and the error curve; returns the statistics and profiles."""
    half_width, r_min, r_max = survey(run.snapshots, run.r0)
    edges = ring_edges(run.r0) if run.ring_run else data_edges(r_min, r_max, N_BINS)
    chosen = pick_figure_snapshot(run.headers, run.ring_run)
    all_stats, profiles, images = [], [], []
    for i, (path, header) in enumerate(zip(run.snapshots, run.headers)):
        parts = read_particles(path)
        stats = snapshot_stats(path, header, parts, edges, run.ring_run)
        profile = radial_profile(parts, edges, stats.name, stats.time, short_label(stats))
        all_stats.append(stats)
        profiles.append(profile)
        if parts["h"] is not None:
            image = render_column_density(parts["xy"], parts["mass"], parts["h"], half_width * run.r0)
            images.append((image.astype(np.float32), stats, path))
        if i == chosen:
            draw_chosen_snapshot(run, parts, stats, profile, out_dir)
    plot_binned_sigma(all_stats, run.r0, os.path.join(out_dir, FIG_BINNED))
    run.figures.append(("Fig. 8: Σ in radial bins, all snapshots: particle mean of the SPH Σ (dots), of Σ without "
                        "its self term (triangles), annulus mass / area (squares)"
                        + (", analytic ring (lines)" if run.ring_run else ""), FIG_BINNED))
    if any(s.tau is not None and s.l1 is not None for s in all_stats):
        plot_error(all_stats, os.path.join(out_dir, FIG_ERROR))
        run.figures.append(("L1 error of the binned Σ against viscous time, with the annulus-mass sampling floor",
                            FIG_ERROR))
    elif run.ring_run:
        run.notes.append("no analytic ring parameters in the headers: no error-vs-time figure.")
    if images:
        draw_maps(run, images, half_width, out_dir)
    else:
        run.notes.append("no SmoothingLength in the snapshots: no column-density maps.")
    write_profiles_csv(profiles, os.path.join(out_dir, PROFILES_CSV))
    return all_stats, profiles


def time_axis(run):
    """Whether times are shown as viscous time (every header has one) and the axis label."""
    use_tau = run.ring_run and all(snapshot_tau(h) is not None for h in run.headers)
    return use_tau, ("viscous time τ" if use_tau else "t (code units)")


def draw_disc_figures(run, all_stats, profiles, out_dir):
    """Radial profiles (discs other than the ring) and the accreted mass over time (every run)."""
    if not run.ring_run:
        plot_profiles(profiles, run.r0, os.path.join(out_dir, FIG_PROFILES))
        run.figures.append(("Radial profiles, all snapshots: Σ (annulus mass / area), v_r, specific angular "
                            "momentum j and mass flux Ṁ = -2π r Σ v_r (inflow > 0); dots: particle means, "
                            "lines: guiding-centre drift", FIG_PROFILES))
    use_tau, xlabel = time_axis(run)
    d = run.diag
    series = (d["tau"] if use_tau else d["time"], d["accreted_mass"]) if d is not None else None
    times = [s.tau if use_tau else s.time for s in all_stats]
    accreted = [s.accreted for s in all_stats]
    points = (np.array(times), np.array(accreted, dtype=float)) if all(a is not None for a in accreted) else None
    m0 = (d["mass"][0] + d["accreted_mass"][0]) if d is not None else all_stats[0].mass + (accreted[0] or 0.0)
    if (series is not None or points is not None) and m0 > 0:
        plot_accreted_mass(series, points, xlabel, m0, os.path.join(out_dir, FIG_ACCRETED))
        run.figures.append(("Mass accreted by the central object over time, relative to the initial disc mass",
                            FIG_ACCRETED))


def draw_run_figures(run, out_dir):
    """Conservation and scaling figures from the CSV files."""
    if run.diag is not None:
        plot_conservation(run.diag, os.path.join(out_dir, FIG_CONSERVATION))
        run.figures.append(("Conservation (diagnostics.csv)", FIG_CONSERVATION))
    else:
        run.notes.append("diagnostics.csv missing or unusable: conservation figure skipped.")
    scaling = read_csv_columns(os.path.join(run.run_dir, "scaling.csv"), ["workers", "particles", "wall_time"])
    if scaling is None:
        return
    t = speedup_table(scaling)
    plot_scaling_curves(t, "speedup", "speedup T(1) / T(p)", os.path.join(out_dir, FIG_SPEEDUP),
                        ideal=lambda p: p)
    plot_scaling_curves(t, "efficiency", "parallel efficiency", os.path.join(out_dir, FIG_EFFICIENCY),
                        ideal=np.ones_like)
    run.figures += [("Fig. 9: speedup (scaling.csv)", FIG_SPEEDUP),
                    ("Fig. 9: parallel efficiency (scaling.csv)", FIG_EFFICIENCY)]
    if "comm_time" in scaling and np.isfinite(scaling["comm_time"]).any():
        plot_scaling_curves(t, "comm", "communication time (s)", os.path.join(out_dir, FIG_COMM))
        run.figures.append(("Fig. 10: communication time against workers (scaling.csv)", FIG_COMM))


def make_report(run_dir, out_dir, sphdisk=None):
    run = load_run(run_dir)
    os.makedirs(out_dir, exist_ok=True)
    if is_sedov_run(run.headers[0]):
        if not sphdisk:
            raise UsageError("a blast wave's report needs the sphdisk binary for its solution: give --sphdisk PATH")
        return write_sedov_report(run, sphdisk, out_dir)
    all_stats, profiles = draw_snapshot_figures(run, out_dir)
    draw_disc_figures(run, all_stats, profiles, out_dir)
    draw_run_figures(run, out_dir)
    md = os.path.join(out_dir, "report.md")
    write_markdown(md, run, all_stats, profiles, rate_sampling_sd(run, all_stats[-1], sphdisk))
    return md


def rate_sampling_sd(run, last, sphdisk):
    """The last snapshot's rate sampling scatter from `sphdisk analyze` (a ring run with a fitted rate
    and the binary at hand), else None: the verdict then omits its noise clause."""
    if not (sphdisk and run.ring_run and last.rate is not None):
        return None
    return analysis(sphdisk, run.snapshots[-1]).get("rate_sampling_sd")


def parse_args(argv):
    p = argparse.ArgumentParser(description="Figures and Markdown report of a sphdisk run directory.")
    p.add_argument("run_dir", metavar="DIR")
    p.add_argument("--out", metavar="OUTDIR", help="output folder (default DIR/report)")
    p.add_argument("--traceback", action="store_true", help="show the full traceback on errors")
    p.add_argument("--sphdisk", metavar="PATH", help="the sphdisk binary (`sphdisk report` passes itself): a blast "
                   "wave's report takes its similarity solution from `sphdisk analyze`")
    return p.parse_args(argv)


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    out_dir = args.out or os.path.join(args.run_dir, "report")
    who = "sphdisk" if args.sphdisk else "report.py"  # `sphdisk report` passes --sphdisk
    try:
        md = make_report(args.run_dir, out_dir, args.sphdisk)
    except UsageError as e:
        print(f"{who}: error: {e}", file=sys.stderr)
        return 2
    except Exception as e:  # one-line message for any other failure
        if args.traceback:
            raise
        print(f"{who}: error: {type(e).__name__}: {' '.join(str(e).split())}", file=sys.stderr)
        return 1
    print(f"wrote {md}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
