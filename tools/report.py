#!/usr/bin/python3
"""Draw the figures of a sphdisk run and write a Markdown report.

    report.py DIR [--out DIR/report]

DIR holds snapshot_000.hdf5, snapshot_001.hdf5, ... (layout: docs/formats.md, "Snapshot files"),
optionally diagnostics.csv, timers.json and scaling.csv. Figures follow the paper's sec. 5
(Figs. 3, 5-10); the analytic viscous ring is P98 eqs. 11-12 in code units (G = M = 1).
Exit status: 0 on success, 2 when DIR is missing or holds no snapshots, 1 on any other error
(always with a one-line message on stderr).
"""
import argparse
import csv
import json
import math
import os
import re
import sys
from dataclasses import dataclass

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend choice)
import numpy as np  # noqa: E402
from scipy.special import ive  # noqa: E402

TAU_FIGURES = 0.09            # snapshot shown in Figs. 5-7 (paper: tau = 0.09)
BIN_RANGE = (0.05, 2.05)      # radial binning of Fig. 8, in units of r0
N_BINS = 50
MAX_POSITIONS = 50_000        # particles drawn in Fig. 5
SEED = 12345                  # fixed seed for the Fig. 5 subsample
SCATTER_CUT = 0.01            # per-particle scatter uses Sigma_ana > 1% of the analytic peak
DPI = 100
FIGSIZE = (6.4, 4.8)          # 640 x 480 px
FIGSIZE_SQUARE = (6.4, 6.4)   # 640 x 640 px

FIG_POSITIONS = "fig5_positions.png"
FIG_SIGMA = "fig6_sigma.png"
FIG_VR = "fig7_vr.png"
FIG_BINNED = "fig8_binned_sigma.png"
FIG_ERROR = "error_vs_time.png"
FIG_CONSERVATION = "conservation.png"
FIG_SPEEDUP = "fig9_speedup.png"
FIG_EFFICIENCY = "fig9_efficiency.png"
FIG_COMM = "fig10_comm_time.png"

DIAG_COLUMNS = ["step", "time", "tau", "dt", "particles", "mass", "accreted_mass", "kinetic_energy",
                "internal_energy", "angular_momentum", "accreted_angular_momentum", "wall_time"]
SNAPSHOT_RE = re.compile(r"^snapshot_(\d{3,})\.hdf5$")


class UsageError(Exception):
    """Bad input directory: reported with exit status 2."""


# ----------------------------------------------------------------------------- analytic solution

@dataclass
class Ring:
    """Analytic spreading ring (P98 eqs. 11-12) at viscous time tau; code units."""
    tau: float
    mass: float
    r0: float
    nu: float | None

    def sigma(self, r):
        x = np.asarray(r, dtype=float) / self.r0
        z = 2.0 * x / self.tau
        return (self.mass / (math.pi * self.r0**2 * self.tau) * x**-0.25
                * np.exp(-(1.0 - x) ** 2 / self.tau) * ive(0.25, z))

    def vr_over_nu(self, r):
        """Radial velocity divided by the kinematic viscosity nu."""
        x = np.asarray(r, dtype=float) / self.r0
        z = 2.0 * x / self.tau
        return 6.0 / (self.r0 * self.tau) * (x - ive(-0.75, z) / ive(0.25, z))

    def peak_sigma(self):
        return float(np.nanmax(self.sigma(self.r0 * np.linspace(1e-3, 3.0, 6000))))


def ring_from_header(header):
    """Ring model for a snapshot header, or None when the run is not a ring run."""
    mass, r0 = header.get("DiskMass"), header.get("RingRadius")
    nu = header.get("KinematicViscosity")
    tau = snapshot_tau(header)
    if mass is None or r0 is None or tau is None or tau <= 0 or mass <= 0 or r0 <= 0:
        return None
    return Ring(float(tau), float(mass), float(r0), float(nu) if nu else None)


def snapshot_tau(header):
    """Viscous time of a snapshot: ViscousTime, else 12 nu t / r0^2, else None."""
    if "ViscousTime" in header:
        return float(header["ViscousTime"])
    nu, r0, t = header.get("KinematicViscosity"), header.get("RingRadius"), header.get("Time")
    if nu is None or r0 is None or t is None or r0 == 0:
        return None
    return 12.0 * float(nu) * float(t) / float(r0) ** 2


# ----------------------------------------------------------------------------- input

def find_snapshots(run_dir):
    """Snapshot paths of a run directory, in output order."""
    if not os.path.isdir(run_dir):
        raise UsageError(f"run directory '{run_dir}' does not exist")
    found = []
    for name in os.listdir(run_dir):
        m = SNAPSHOT_RE.match(name)
        if m:
            found.append((int(m.group(1)), os.path.join(run_dir, name)))
    if not found:
        raise UsageError(f"no snapshot_*.hdf5 files in '{run_dir}'")
    return [path for _, path in sorted(found)]


def plain(value):
    """HDF5 attribute value as a plain Python value (bytes decoded, 1-element arrays unwrapped)."""
    if isinstance(value, (bytes, np.bytes_)):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.ndarray):
        if value.dtype.kind == "S":
            value = np.char.decode(value, "utf-8", "replace")
        return value.item() if value.size == 1 else value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return value


def read_attrs(path, group):
    with h5py.File(path, "r") as f:
        if group not in f:
            return None
        return {str(k): plain(v) for k, v in f[group].attrs.items()}


def read_header(path):
    header = read_attrs(path, "Header")
    if header is None:
        raise ValueError(f"{path}: no /Header group")
    return header


# sigma_2 w(0) of the 2D kernels (src/physics/kernels.hpp): the self term of the summation density
# is m sigma_2 w(0) / h^2.
SELF_WEIGHT_2D = {"cubic": 10 / (7 * math.pi), "wendland_c2": 7 / (4 * math.pi), "wendland_c4": 9 / (4 * math.pi)}


def read_particles(path):
    """Cylindrical radius, radial velocity, Sigma, the self-term-free Sigma (None without
    smoothing lengths) and x-y positions of the gas particles."""
    with h5py.File(path, "r") as f:
        gas = f["PartType0"]
        pos = np.asarray(gas["Coordinates"][:], dtype=float).reshape(-1, 3)
        vel = np.asarray(gas["Velocities"][:], dtype=float).reshape(-1, 3)
        sigma = np.asarray(gas["Density"][:], dtype=float)
        mass = np.asarray(gas["Masses"][:], dtype=float)
        h = np.asarray(gas["SmoothingLength"][:], dtype=float) if "SmoothingLength" in gas else None
        kernel = f["Parameters"].attrs.get("sph.kernel", b"cubic") if "Parameters" in f else b"cubic"
        kernel = (kernel.decode() if isinstance(kernel, bytes) else str(kernel)).strip('"')
    r = np.hypot(pos[:, 0], pos[:, 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        vr = (pos[:, 0] * vel[:, 0] + pos[:, 1] * vel[:, 1]) / r
        noself = sigma - mass * SELF_WEIGHT_2D.get(kernel, SELF_WEIGHT_2D["cubic"]) / h**2 if h is not None else None
    return {"xy": pos[:, :2], "r": r, "vr": vr, "sigma": sigma, "sigma_noself": noself, "mass": mass}


def read_csv_columns(path, required):
    """Columns of a CSV file as float arrays; None when absent, empty or lacking a required column."""
    if not os.path.isfile(path):
        return None
    with open(path, newline="") as fh:
        rows = [row for row in csv.DictReader(fh) if row]
    if not rows or any(c not in rows[0] for c in required):
        return None
    return {c: np.array([to_float(row.get(c)) for row in rows]) for c in rows[0] if c is not None}


def to_float(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def read_timers(path):
    if not os.path.isfile(path):
        return None
    with open(path) as fh:
        data = json.load(fh)
    return data if isinstance(data, dict) else None


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


def bin_edges(r0):
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


def annulus_mean_analytic(ring, edges, samples=400):
    """Area-weighted analytic mean of Sigma over each annulus (midpoint rule in r)."""
    out = np.empty(len(edges) - 1)
    for k, (lo, hi) in enumerate(zip(edges[:-1], edges[1:])):
        rr = lo + (hi - lo) * (np.arange(samples) + 0.5) / samples
        out[k] = np.sum(ring.sigma(rr) * rr) / np.sum(rr)
    return out


def particle_scatter(sigma, sigma_ana, peak):
    """std of Sigma_sph / Sigma_ana - 1 over particles with Sigma_ana > SCATTER_CUT * peak."""
    used = np.isfinite(sigma) & np.isfinite(sigma_ana) & (sigma_ana > SCATTER_CUT * peak)
    return float(np.std(sigma[used] / sigma_ana[used] - 1.0)) if used.sum() > 1 else None


def snapshot_stats(path, header, parts):
    ring = ring_from_header(header)
    r0 = ring.r0 if ring else float(header.get("RingRadius", 1.0) or 1.0)
    edges = bin_edges(r0)
    mean_sph, counts = binned_mean(parts["r"], parts["sigma"], edges)
    mean_noself = binned_mean(parts["r"], parts["sigma_noself"], edges)[0] if parts.get("sigma_noself") is not None else None
    mass_sigma = annulus_sigma(parts["r"], parts["mass"], edges)
    mean_ana = l1 = scatter = mass_ana = l1_mass = None
    if ring:
        sigma_ana = ring.sigma(parts["r"])
        mean_ana, _ = binned_mean(parts["r"], sigma_ana, edges)
        l1 = l1_error(mean_sph, mean_ana, counts)
        scatter = particle_scatter(parts["sigma"], sigma_ana, ring.peak_sigma())
        mass_ana = annulus_mean_analytic(ring, edges)
        l1_mass = float(np.sum(np.abs(mass_sigma - mass_ana)) / np.sum(mass_ana))
    return SnapshotStats(os.path.basename(path), float(header.get("Time", math.nan)),
                         snapshot_tau(header), len(parts["r"]), ring, 0.5 * (edges[1:] + edges[:-1]),
                         mean_sph, mean_ana, counts, l1, scatter, mass_sigma, mass_ana, l1_mass, mean_noself)


def pick_figure_snapshot(headers):
    """Index of the snapshot nearest tau = TAU_FIGURES, else the last one."""
    taus = [snapshot_tau(h) for h in headers]
    if any(t is None for t in taus):
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


# ----------------------------------------------------------------------------- figures

def new_figure(figsize=FIGSIZE, **kwargs):
    return plt.subplots(figsize=figsize, dpi=DPI, layout="constrained", **kwargs)


def save(fig, path):
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def title_for(stats):
    tau = f", τ = {stats.tau:.4g}" if stats.tau is not None else ""
    return f"{stats.name}: t = {stats.time:.4g}{tau}, N = {stats.particles}"


def plot_positions(parts, stats, path):
    xy = parts["xy"]
    if len(xy) > MAX_POSITIONS:
        xy = xy[np.random.default_rng(SEED).choice(len(xy), MAX_POSITIONS, replace=False)]
    fig, ax = new_figure(FIGSIZE_SQUARE)
    ax.plot(xy[:, 0], xy[:, 1], ls="none", marker=".", ms=0.6, color="k", alpha=0.6)
    lim = 1.05 * float(np.nanquantile(np.abs(xy), 0.999)) if len(xy) else 1.0
    ax.set(xlim=(-lim, lim), ylim=(-lim, lim), aspect="equal", xlabel="x (code units)",
           ylabel="y (code units)",
           title=f"{title_for(stats)}" + (f"\n{len(xy)} random particles shown" if len(xy) < stats.particles else ""))
    save(fig, path)


def radius_grid(ring, parts):
    r0 = ring.r0 if ring else 1.0
    r_max = max(BIN_RANGE[1], 1.02 * np.nanmax(parts["r"] / r0, initial=0.0))
    return r0 * np.linspace(BIN_RANGE[0], r_max, 2000)


def plot_sigma(parts, stats, path):
    fig, ax = new_figure()
    ax.plot(parts["r"], parts["sigma"], ls="none", marker=".", ms=1, alpha=0.3, color="tab:blue",
            label="particles")
    if stats.ring:
        rr = radius_grid(stats.ring, parts)
        ax.plot(rr, stats.ring.sigma(rr), color="tab:red", lw=1.5, label="analytic (P98 eq. 11)")
    ax.set(xlabel="r (code units)", ylabel="Σ (code units)", title=title_for(stats),
           xlim=(0, None), ylim=(0, None))
    ax.legend(loc="upper right", markerscale=8)
    save(fig, path)


def plot_vr(parts, stats, path):
    nu = stats.ring.nu if stats.ring else None
    scale, unit = (1.0 / nu, "v_r / ν (1 / code length)") if nu else (1.0, "v_r (code units)")
    vr = parts["vr"] * scale
    fig, ax = new_figure()
    ax.plot(parts["r"], vr, ls="none", marker=".", ms=1, alpha=0.3, color="tab:blue", label="particles")
    ylim = list(np.nanpercentile(vr, [0.5, 99.5])) if np.isfinite(vr).any() else [-1.0, 1.0]
    if nu:
        rr = radius_grid(stats.ring, parts)
        ana = stats.ring.vr_over_nu(rr)
        inside = (rr >= np.nanmin(parts["r"])) & (rr <= np.nanmax(parts["r"]))
        ax.plot(rr, ana, color="tab:red", lw=1.5, label="analytic (P98 eq. 12)")
        ylim = [min(ylim[0], np.nanmin(ana[inside])), max(ylim[1], np.nanmax(ana[inside]))]
    pad = 0.1 * (ylim[1] - ylim[0] or 1.0)
    ax.axhline(0.0, color="0.5", lw=0.5)
    ax.set(xlabel="r (code units)", ylabel=unit, title=title_for(stats), xlim=(0, None),
           ylim=(ylim[0] - pad, ylim[1] + pad))
    ax.legend(loc="upper left", markerscale=8)
    save(fig, path)


def plot_binned_sigma(all_stats, path):
    fig, ax = new_figure()
    colours = plt.cm.viridis(np.linspace(0.0, 0.9, len(all_stats)))
    for stats, colour in zip(all_stats, colours):
        label = f"τ = {stats.tau:.3g}" if stats.tau is not None else stats.name
        ax.plot(stats.centres, stats.mean_sph, ls="none", marker="o", ms=3, color=colour, label=label)
        ax.plot(stats.centres, stats.mass_sigma, ls="none", marker="s", ms=4, mfc="none", mew=0.7, color=colour)
        if stats.mean_noself is not None:
            ax.plot(stats.centres, stats.mean_noself, ls="none", marker="^", ms=3, mfc="none", mew=0.7, color=colour)
        if stats.ring:
            rr = np.linspace(stats.centres[0], stats.centres[-1], 800)
            ax.plot(rr, stats.ring.sigma(rr), color=colour, lw=1)
    ax.set(xlabel="r (code units)", ylabel="⟨Σ⟩ per bin (code units)",
           title=f"Σ in {N_BINS} bins: particle mean of the SPH Σ (dots) and of Σ without its self term m W(0, h)\n"
                 "(triangles: unbiased on disordered particles), annulus mass/area (squares), analytic (lines)",
           ylim=(0, None))
    ax.title.set_fontsize("small")
    ax.legend(fontsize="small")
    save(fig, path)


def plot_error(all_stats, path):
    pts = [(s.tau, s.l1, s.l1_mass) for s in all_stats if s.tau is not None and s.l1 is not None]
    fig, ax = new_figure()
    tau, l1, l1_mass = np.array(pts).T
    ax.plot(tau, l1, marker="o", color="tab:blue", label="particle Σ (SPH estimate)")
    ax.plot(tau, l1_mass, marker="s", color="tab:orange", label="annulus mass / area")
    if np.all(l1 > 0) and np.all(l1_mass > 0):
        ax.set_yscale("log")
    ax.legend(fontsize="small")
    ax.set(xlabel="viscous time τ", ylabel="L1 error of binned Σ",
           title=(f"Σ|⟨Σ_sph⟩ - ⟨Σ_ana⟩| / Σ⟨Σ_ana⟩, "
                  f"{N_BINS} bins in [{BIN_RANGE[0]}, {BIN_RANGE[1]}] r0"))
    ax.grid(alpha=0.3)
    save(fig, path)


def conservation_series(diag):
    """Relative changes of the conserved quantities in diagnostics.csv."""
    mass = diag["mass"] + diag["accreted_mass"]
    ang = diag["angular_momentum"] + diag["accreted_angular_momentum"]
    energy = diag["kinetic_energy"] + diag["internal_energy"]
    return [
        ("(mass + accreted) / M₀ - 1", relative_change(mass)),
        ("accreted mass / M₀", diag["accreted_mass"] / mass[0] if mass[0] else diag["accreted_mass"]),
        ("(L_z + accreted L_z) / L₀ - 1", relative_change(ang)),
        ("(E_kin + E_int) / E₀ - 1\n(no potential energy)", relative_change(energy)),
    ]


def relative_change(values):
    ref = values[0]
    return values / ref - 1.0 if ref else values - ref


def plot_conservation(diag, path):
    use_tau = np.isfinite(diag["tau"]).all() and np.ptp(diag["tau"]) > 0
    x, xlabel = (diag["tau"], "viscous time τ") if use_tau else (diag["time"], "time (code units)")
    fig, axes = new_figure(nrows=2, ncols=2, sharex=True)
    for ax, (label, y) in zip(axes.flat, conservation_series(diag)):
        ax.plot(x, y, color="tab:blue", lw=1)
        ax.set_title(label, fontsize="small")
        ax.tick_params(labelsize="x-small")
        ax.yaxis.get_offset_text().set_fontsize("x-small")
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel(xlabel, fontsize="small")
    save(fig, path)


def plot_scaling_curves(table, key, ylabel, title, path, ideal=None):
    fig, ax = new_figure()
    for n, row in table.items():
        if row[key] is not None and np.isfinite(row[key]).any():
            ax.plot(row["workers"], row[key], marker="o", label=f"{n} particles")
    if ideal is not None:
        p = np.unique(np.concatenate([row["workers"] for row in table.values()]))
        ax.plot(p, ideal(p), color="0.5", ls="--", lw=1, label="ideal")
    ax.set(xlabel="workers", ylabel=ylabel, title=title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    save(fig, path)


def plot_speedup(table, path):
    plot_scaling_curves(table, "speedup", "speedup T(1) / T(p)", "Speedup", path, ideal=lambda p: p)


def plot_efficiency(table, path):
    plot_scaling_curves(table, "efficiency", "parallel efficiency speedup / p", "Parallel efficiency",
                        path, ideal=np.ones_like)


def plot_comm(table, path):
    plot_scaling_curves(table, "comm", "communication time (s)", "Communication time", path)


# ----------------------------------------------------------------------------- report

def fmt(value):
    """Compact text for a table cell."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "–"
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(fmt(v) for v in value) + "]"
    return str(value).replace("|", "\\|").replace("\n", " ")


def table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(fmt(c) for c in row) + " |" for row in rows]
    return lines


def section_run(run_dir, snapshots, header0):
    keys = ["Code", "Dimension", "DiskMass", "RingRadius", "KinematicViscosity", "ViscousTime", "Time"]
    rows = [(k, header0[k]) for k in keys if k in header0]
    return ([f"Run directory: `{os.path.abspath(run_dir)}`, {len(snapshots)} snapshots.", "",
             "Initial conditions (`/Header` of snapshot_000, code units G = M = 1):", ""]
            + table(["attribute", "value"], rows) + [""])


def section_parameters(params):
    lines = ["## Parameters", ""]
    if not params:
        return lines + ["snapshot_000 has no `/Parameters` attributes.", ""]
    return lines + table(["parameter", "value"], sorted(params.items())) + [""]


def section_accuracy(all_stats):
    lines = ["## Accuracy against the analytic ring solution", "",
             f"L1: binned Σ error over {N_BINS} bins in [{BIN_RANGE[0]}, {BIN_RANGE[1]}] r0 "
             "(analytic bin average = mean of Σ_ana at the particles' radii; empty bins skipped). "
             f"Scatter: std of Σ_sph/Σ_ana - 1 over particles with Σ_ana > {SCATTER_CUT:.0%} of its peak.", ""]
    rows = [(s.name, s.time, s.tau, s.particles, s.l1, s.l1_mass, s.scatter) for s in all_stats]
    return lines + table(["snapshot", "time", "τ", "particles", "L1 binned particle Σ", "L1 annulus mass/area",
                          "particle scatter"], rows) + [""]


def section_diagnostics(diag, timers):
    lines = ["## Run diagnostics", ""]
    if diag is None:
        lines += ["diagnostics.csv missing, empty or lacking columns: conservation figure and wall time skipped.", ""]
    else:
        last = {c: diag[c][-1] for c in ("step", "tau", "wall_time")}
        lines += [f"Wall time: {last['wall_time']:.6g} s (diagnostics.csv last row: step "
                  f"{fmt(last['step'])}, τ = {last['tau']:.6g}).", ""]
    if timers:
        lines += ["Timers (timers.json):", ""] + table(["phase", "seconds"], list(timers.items())) + [""]
    return lines


def section_figures(figures):
    lines = ["## Figures", ""]
    for caption, name in figures:
        lines += [f"### {caption}", "", f"![{caption}]({name})", ""]
    return lines


def write_markdown(path, run_dir, snapshots, header0, params, all_stats, diag, timers, figures, notes):
    lines = [f"# sphdisk run report: {os.path.basename(os.path.abspath(run_dir))}", ""]
    lines += section_run(run_dir, snapshots, header0)
    lines += section_parameters(params)
    lines += section_accuracy(all_stats)
    lines += section_diagnostics(diag, timers)
    lines += section_figures(figures)
    if notes:
        lines += ["## Notes", ""] + [f"- {n}" for n in notes] + [""]
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("\n".join(lines))


# ----------------------------------------------------------------------------- driver

def draw_snapshot_figures(snapshots, headers, out_dir, figures, notes):
    """Figs. 5-8 and the error curve; returns the per-snapshot statistics."""
    chosen = pick_figure_snapshot(headers)
    all_stats = []
    for i, (path, header) in enumerate(zip(snapshots, headers)):
        parts = read_particles(path)
        stats = snapshot_stats(path, header, parts)
        all_stats.append(stats)
        if i == chosen:
            where = f"{stats.name}, τ = {stats.tau:.4g}" if stats.tau is not None else stats.name
            plot_positions(parts, stats, os.path.join(out_dir, FIG_POSITIONS))
            plot_sigma(parts, stats, os.path.join(out_dir, FIG_SIGMA))
            plot_vr(parts, stats, os.path.join(out_dir, FIG_VR))
            figures += [(f"Fig. 5: particle positions ({where})", FIG_POSITIONS),
                        (f"Fig. 6: particle Σ vs radius ({where})", FIG_SIGMA),
                        (f"Fig. 7: particle radial velocity vs radius ({where})", FIG_VR)]
    plot_binned_sigma(all_stats, os.path.join(out_dir, FIG_BINNED))
    figures.append(("Fig. 8: Σ averaged in radial bins, all snapshots", FIG_BINNED))
    if any(s.tau is not None and s.l1 is not None for s in all_stats):
        plot_error(all_stats, os.path.join(out_dir, FIG_ERROR))
        figures.append(("Binned-Σ L1 error vs viscous time", FIG_ERROR))
    else:
        notes.append("no analytic ring parameters in the headers: no error-vs-time figure.")
    return all_stats


def draw_run_figures(run_dir, out_dir, figures, notes):
    """Conservation and scaling figures from the CSV files; returns the diagnostics."""
    diag = read_csv_columns(os.path.join(run_dir, "diagnostics.csv"), DIAG_COLUMNS)
    if diag is not None:
        plot_conservation(diag, os.path.join(out_dir, FIG_CONSERVATION))
        figures.append(("Conservation (diagnostics.csv)", FIG_CONSERVATION))
    else:
        notes.append("diagnostics.csv missing or unusable: conservation figure skipped.")
    scaling = read_csv_columns(os.path.join(run_dir, "scaling.csv"), ["workers", "particles", "wall_time"])
    if scaling is not None:
        table_ = speedup_table(scaling)
        plot_speedup(table_, os.path.join(out_dir, FIG_SPEEDUP))
        plot_efficiency(table_, os.path.join(out_dir, FIG_EFFICIENCY))
        figures += [("Fig. 9: speedup (scaling.csv)", FIG_SPEEDUP),
                    ("Fig. 9: parallel efficiency (scaling.csv)", FIG_EFFICIENCY)]
        if "comm_time" in scaling and np.isfinite(scaling["comm_time"]).any():
            plot_comm(table_, os.path.join(out_dir, FIG_COMM))
            figures.append(("Fig. 10: communication time vs workers (scaling.csv)", FIG_COMM))
    return diag


def make_report(run_dir, out_dir):
    snapshots = find_snapshots(run_dir)
    headers = [read_header(p) for p in snapshots]
    os.makedirs(out_dir, exist_ok=True)
    figures, notes = [], []
    all_stats = draw_snapshot_figures(snapshots, headers, out_dir, figures, notes)
    diag = draw_run_figures(run_dir, out_dir, figures, notes)
    timers = read_timers(os.path.join(run_dir, "timers.json"))
    params = read_attrs(snapshots[0], "Parameters")
    md = os.path.join(out_dir, "report.md")
    write_markdown(md, run_dir, snapshots, headers[0], params, all_stats, diag, timers, figures, notes)
    return md


def parse_args(argv):
    p = argparse.ArgumentParser(description="Figures and Markdown report of a sphdisk run directory.")
    p.add_argument("run_dir", metavar="DIR")
    p.add_argument("--out", metavar="OUTDIR", help="output folder (default DIR/report)")
    p.add_argument("--traceback", action="store_true", help="show the full traceback on errors")
    return p.parse_args(argv)


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    out_dir = args.out or os.path.join(args.run_dir, "report")
    try:
        md = make_report(args.run_dir, out_dir)
    except UsageError as e:
        print(f"report.py: error: {e}", file=sys.stderr)
        return 2
    except Exception as e:  # one-line message for any other failure
        if args.traceback:
            raise
        print(f"report.py: error: {type(e).__name__}: {' '.join(str(e).split())}", file=sys.stderr)
        return 1
    print(f"wrote {md}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
