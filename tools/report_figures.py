"""The figures of the run report drawn with matplotlib from the per-snapshot statistics of report.py:
Figs. 5-8 of the paper's sec. 5, the error curve, conservation and scaling (style: report_style.py).
"""
import math

import matplotlib.pyplot as plt
import numpy as np

from report_style import (COLUMN, COLUMN_SQUARE, R_LABEL, WIDE, WIDE_GRID, X_LABEL, Y_LABEL, corner_note,
                          new_figure, save)
from ring_model import BIN_RANGE, N_BINS
from run_data import conservation_series

MAX_POSITIONS = 50_000        # particles drawn in Fig. 5
SEED = 12345                  # fixed seed for the Fig. 5 subsample


def short_label(stats):
    """Legend label of a snapshot: its viscous time for a ring run, else its time."""
    return f"τ = {stats.tau:.3g}" if stats.tau is not None and stats.ring else f"t = {stats.time:.4g}"


def snapshot_note(stats):
    """Corner text of a snapshot's figures: time (and viscous time of a ring run) and particle count."""
    tau = f", τ = {stats.tau:.3g}" if stats.tau is not None and stats.ring else ""
    return f"t = {stats.time:.4g}{tau}\nN = {stats.particles}"


def radius_grid(ring, parts):
    """Radii for the analytic curves: the binned range, or out to the farthest particle."""
    r_max = max(BIN_RANGE[1], 1.02 * np.nanmax(parts["r"] / ring.r0, initial=0.0))
    return ring.r0 * np.linspace(BIN_RANGE[0], r_max, 2000)


def plot_positions(parts, stats, r0, path):
    xy = parts["xy"] / r0
    if len(xy) > MAX_POSITIONS:
        xy = xy[np.random.default_rng(SEED).choice(len(xy), MAX_POSITIONS, replace=False)]
    fig, ax = new_figure(COLUMN_SQUARE)
    ax.plot(xy[:, 0], xy[:, 1], ls="none", marker=".", ms=0.5, mew=0, color="k", alpha=0.6, rasterized=True)
    lim = 1.05 * float(np.nanquantile(np.abs(xy), 0.999)) if len(xy) else 1.0
    ax.set(xlim=(-lim, lim), ylim=(-lim, lim), aspect="equal", xlabel=X_LABEL, ylabel=Y_LABEL)
    shown = f"\n{len(xy)} shown" if len(xy) < stats.particles else ""
    corner_note(ax, snapshot_note(stats) + shown)
    save(fig, path)


def particle_dots(ax, x, y):
    """One small dot per particle (a bitmap inside the PDF: a million vector markers would make it
    huge), with a legend entry large enough to see."""
    ax.plot(x, y, ls="none", marker=".", ms=1, mew=0, alpha=0.3, color="tab:blue", rasterized=True)
    ax.plot([], [], ls="none", marker=".", ms=4, color="tab:blue", alpha=0.6, label="particles")


def radius_limits(r_over_r0):
    """x range of a plot against r/r0: the particles' radii with a margin."""
    lo, hi = np.nanmin(r_over_r0, initial=np.inf), np.nanmax(r_over_r0, initial=-np.inf)
    if not np.isfinite(lo) or not np.isfinite(hi):
        return 0.0, None
    pad = 0.05 * (hi - lo or 1.0)
    return max(0.0, lo - pad), hi + pad


def plot_sigma(parts, stats, r0, path):
    fig, ax = new_figure(COLUMN)
    particle_dots(ax, parts["r"] / r0, parts["sigma"])
    if stats.ring:
        rr = radius_grid(stats.ring, parts)
        ax.plot(rr / r0, stats.ring.sigma(rr), color="tab:red", label="analytic (P98 eq. 11)")
    ax.set(xlabel=R_LABEL, ylabel=r"$\Sigma$ ($M\,r_0^{-2}$)", xlim=radius_limits(parts["r"] / r0), ylim=(0, None))
    ax.legend(loc="upper right")
    corner_note(ax, snapshot_note(stats), "upper left")
    save(fig, path)


def vr_panel(ax, r_over_r0, values, centres, binned, analytic, ylabel, note=None):
    """One panel of Fig. 7: particles (dots), mass-weighted bin means (circles) and the analytic curve."""
    particle_dots(ax, r_over_r0, values)
    ax.plot(centres, binned, ls="none", marker="o", ms=2.5, color="k", label="bin mean")
    ylim = list(np.nanpercentile(values, [0.5, 99.5])) if np.isfinite(values).any() else [-1.0, 1.0]
    if analytic is not None:
        ax.plot(*analytic, color="tab:red", label="analytic (P98 eq. 12)")
        ylim = [min(ylim[0], np.nanmin(analytic[1])), max(ylim[1], np.nanmax(analytic[1]))]
    ylim = [min(ylim[0], 0.0), max(ylim[1], 0.0)]  # v_r = 0 in view: no round-off-wide axis for uniform flows
    pad = 0.1 * (ylim[1] - ylim[0] or 1.0)
    ax.axhline(0.0, color="0.5", lw=0.5)
    ax.set(xlabel=R_LABEL, ylabel=ylabel, xlim=radius_limits(r_over_r0), ylim=(ylim[0] - pad, ylim[1] + pad))
    ax.legend(loc="upper left", title=note, title_fontsize=7, alignment="left")


def plot_vr(parts, stats, profile, r0, path):
    """Fig. 7: the particles' own v_r (epicyclic noise) beside the guiding-centre drift."""
    nu = stats.ring.nu if stats.ring else None
    scale, unit = (1.0 / nu, r"$v_r/\nu$ ($r_0^{-1}$)") if nu else (1.0, r"$v_r$ ($\sqrt{GM/r_0}$)")
    analytic = None
    if nu:
        rr = radius_grid(stats.ring, parts)
        inside = (rr >= np.nanmin(parts["r"])) & (rr <= np.nanmax(parts["r"]))
        analytic = (rr[inside] / r0, stats.ring.vr_over_nu(rr[inside]))
    fig, (left, right) = new_figure(WIDE, ncols=2)
    x = parts["r"] / r0
    vr_panel(left, x, parts["vr"] * scale, profile.centres / r0, profile.vr * scale, analytic, unit,
             snapshot_note(stats).replace("\n", ", "))
    left.set_title("particle velocity", fontsize=8)
    if parts["drift"] is not None:
        vr_panel(right, x, parts["drift"] * scale, profile.centres / r0, profile.vr_drift * scale, analytic,
                 unit.replace("v_r", r"\dot r_g"))
    else:
        right.text(0.5, 0.5, "no Acceleration in the snapshot:\nno guiding-centre drift", ha="center",
                   va="center", transform=right.transAxes)
        right.set(xlabel=R_LABEL)
    right.set_title(r"guiding-centre drift $\dot r_g = 2 j\,(x a_y - y a_x)/GM$", fontsize=8)
    save(fig, path)


def plot_binned_sigma(all_stats, r0, path):
    fig, ax = new_figure(COLUMN)
    colours = plt.cm.viridis(np.linspace(0.0, 0.9, len(all_stats)))
    for stats, colour in zip(all_stats, colours):
        x = stats.centres / r0
        ax.plot(x, stats.mean_sph, ls="none", marker="o", ms=2, color=colour, label=short_label(stats))
        ax.plot(x, stats.mass_sigma, ls="none", marker="s", ms=2.5, mfc="none", mew=0.5, color=colour)
        if stats.mean_noself is not None:
            ax.plot(x, stats.mean_noself, ls="none", marker="^", ms=2, mfc="none", mew=0.5, color=colour)
        if stats.ring:
            rr = np.linspace(stats.centres[0], stats.centres[-1], 800)
            ax.plot(rr / r0, stats.ring.sigma(rr), color=colour, lw=0.8)
    styles = [("o", "none", "SPH Σ"), ("^", "none", "without self term"), ("s", "none", "annulus mass / area")]
    if any(s.ring for s in all_stats):
        styles.append(("", "-", "analytic"))
    for marker, ls, label in styles:
        ax.plot([], [], marker=marker, ls=ls, mfc="none" if marker in "^s" else "0.4", color="0.4", label=label)
    populated = np.concatenate([s.centres[s.counts > 0] for s in all_stats]) / r0
    top = max((np.nanmax(v, initial=0.0) for s in all_stats for v in (s.mean_sph, s.mass_sigma)), default=0.0)
    ax.set(xlabel=R_LABEL, ylabel=r"$\langle\Sigma\rangle$ per bin ($M\,r_0^{-2}$)", xlim=radius_limits(populated),
           ylim=(0, 1.5 * top if top > 0 else None))
    ax.legend(fontsize=6, ncols=2, loc="upper center")
    save(fig, path)


def plot_error(all_stats, path):
    pts = [(s.tau, s.l1, s.l1_mass, s.floor or math.nan) for s in all_stats if s.tau is not None and s.l1 is not None]
    fig, ax = new_figure(COLUMN)
    tau, l1, l1_mass, floor = np.array(pts).T
    ax.plot(tau, l1, marker="o", color="tab:blue", label="particle Σ (SPH estimate)")
    ax.plot(tau, l1_mass, marker="s", color="tab:orange", label="annulus mass / area")
    ax.plot(tau, floor, ls="--", color="0.4", label="sampling floor")
    if np.all(l1 > 0) and np.all(l1_mass > 0):
        ax.set_yscale("log")
    ax.legend()
    ax.set(xlabel="viscous time τ", ylabel=f"L1 error of Σ in {N_BINS} bins")
    ax.grid(alpha=0.3)
    save(fig, path)


def plot_conservation(diag, path):
    use_tau = np.isfinite(diag["tau"]).all() and np.ptp(diag["tau"]) > 0
    x, xlabel = (diag["tau"], "viscous time τ") if use_tau else (diag["time"], "t (code units)")
    fig, axes = new_figure(WIDE_GRID, nrows=2, ncols=2, sharex=True)
    for ax, (label, y) in zip(axes.flat, conservation_series(diag)):
        ax.plot(x, y, color="tab:blue")
        ax.set_title(label)
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel(xlabel)
    save(fig, path)


def plot_scaling_curves(table, key, ylabel, path, ideal=None):
    fig, ax = new_figure(COLUMN)
    for n, row in table.items():
        if row[key] is not None and np.isfinite(row[key]).any():
            ax.plot(row["workers"], row[key], marker="o", label=f"{n} particles")
    if ideal is not None:
        p = np.unique(np.concatenate([row["workers"] for row in table.values()]))
        ax.plot(p, ideal(p), color="0.5", ls="--", label="ideal")
    ax.set(xlabel="workers", ylabel=ylabel)
    ax.grid(alpha=0.3)
    ax.legend()
    save(fig, path)

