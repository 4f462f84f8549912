"""Radial profiles of any disc around the central mass, without reference to an analytic solution:
Sigma (annulus mass / area), the mass-weighted mean v_r and guiding-centre drift, the specific angular
momentum j and the mass flux Mdot = -2 pi r Sigma <v_r> (inflow positive), per radial bin; and the
accreted mass over time. Code units G = M = 1 (docs/physics.md sec. 4).
"""
import csv
from dataclasses import dataclass

import matplotlib.pyplot as plt
import numpy as np

from report_style import COLUMN, R_LABEL, WIDE_GRID, new_figure, save

PROFILES_CSV = "profiles.csv"
PROFILE_FIELDS = ["r_lo", "r_hi", "count", "sigma", "vr", "vr_drift", "j", "mdot", "mdot_drift"]


@dataclass
class Profile:
    """Per-bin values of one snapshot; NaN where a bin holds no particle (or no accelerations)."""
    name: str
    time: float
    label: str
    edges: np.ndarray
    count: np.ndarray
    sigma: np.ndarray
    vr: np.ndarray
    vr_drift: np.ndarray
    j: np.ndarray

    @property
    def centres(self):
        return 0.5 * (self.edges[1:] + self.edges[:-1])

    def mdot(self, vr):
        """Mass flux through the bin's mid radius, -2 pi r Sigma v_r (positive inward)."""
        return -2.0 * np.pi * self.centres * self.sigma * vr


def guiding_centre_drift(xy, vel, acc):
    """d r_g / dt = 2 j (x a_y - y a_x) / (G M) with j = x v_y - y v_x and r_g = j^2 / (G M): only the
    torque changes j, so the epicycles of the particles' own v_r drop out (docs/physics.md sec. 4)."""
    j = xy[:, 0] * vel[:, 1] - xy[:, 1] * vel[:, 0]
    return 2.0 * j * (xy[:, 0] * acc[:, 1] - xy[:, 1] * acc[:, 0])


def mass_weighted(r, mass, values, edges):
    """Mass-weighted mean of values per bin; NaN in empty bins or where values is None."""
    if values is None:
        return np.full(len(edges) - 1, np.nan)
    m, _ = np.histogram(r, bins=edges, weights=mass)
    s, _ = np.histogram(r, bins=edges, weights=mass * values)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(m > 0, s / np.where(m > 0, m, 1.0), np.nan)


def radial_profile(parts, edges, name, time, label):
    """Profile of one snapshot's particles (read_particles of report.py) on the bin edges; label names
    it in legends."""
    r, mass = parts["r"], parts["mass"]
    count, _ = np.histogram(r, bins=edges)
    annulus_mass, _ = np.histogram(r, bins=edges, weights=mass)
    sigma = annulus_mass / (np.pi * (edges[1:] ** 2 - edges[:-1] ** 2))
    return Profile(name, time, label, edges, count, sigma, mass_weighted(r, mass, parts["vr"], edges),
                   mass_weighted(r, mass, parts.get("drift"), edges), mass_weighted(r, mass, parts["j"], edges))


def data_edges(r_min, r_max, bins):
    """Equal-width bins over the radii the particles cover."""
    lo = max(0.0, float(r_min))
    return np.linspace(lo, max(float(r_max), lo * 1.01 + 1e-12), bins + 1)


def csv_cell(value):
    """CSV text of a number; empty for NaN (empty bins) so no reader meets a NaN literal."""
    return "" if not np.isfinite(value) else f"{value:.9g}"


def write_profiles_csv(profiles, path):
    """All snapshots' profiles in one table: snapshot, time, then PROFILE_FIELDS."""
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["snapshot", "time", *PROFILE_FIELDS])
        for p in profiles:
            cols = [p.edges[:-1], p.edges[1:], p.count, p.sigma, p.vr, p.vr_drift, p.j,
                    p.mdot(p.vr), p.mdot(p.vr_drift)]
            for row in zip(*cols):
                w.writerow([p.name, csv_cell(p.time), *(csv_cell(float(v)) for v in row)])


def plot_profiles(profiles, r0, path):
    """2 x 2 panels: Sigma, v_r (mean: dots, drift: line), j and Mdot (mean: dots, drift: line), one colour
    per snapshot; radii in r0."""
    fig, axes = new_figure(WIDE_GRID, nrows=2, ncols=2, sharex=True)
    (ax_s, ax_v), (ax_j, ax_m) = axes
    colours = plt.cm.viridis(np.linspace(0.0, 0.9, len(profiles)))
    for p, c in zip(profiles, colours):
        x = p.centres / r0
        ax_s.plot(x, p.sigma, color=c, label=p.label)
        ax_v.plot(x, p.vr, ls="none", marker=".", color=c)
        ax_v.plot(x, p.vr_drift, color=c)
        ax_j.plot(x, p.j, color=c)
        ax_m.plot(x, p.mdot(p.vr), ls="none", marker=".", color=c)
        ax_m.plot(x, p.mdot(p.vr_drift), color=c)
    if any(np.any(p.sigma > 0) for p in profiles):
        ax_s.set_yscale("log")  # empty bins (Sigma = 0) drop out
    ax_s.set_ylabel(r"$\Sigma$ ($M\,r_0^{-2}$)")
    ax_v.set_ylabel(r"$v_r$ ($\sqrt{GM/r_0}$)")
    ax_j.set_ylabel(r"$j$ ($\sqrt{GM r_0}$)")
    ax_m.set_ylabel(r"$\dot M = -2\pi r \Sigma v_r$ ($M\,\sqrt{GM/r_0^3}$)")
    for ax in (ax_v, ax_m):
        ax.axhline(0.0, color="0.6", lw=0.5)
        ax.plot([], [], ls="none", marker=".", color="0.3", label="particle mean")
        ax.plot([], [], color="0.3", label="guiding-centre drift")
        ax.legend(loc="best")
    for ax in axes[1]:
        ax.set_xlabel(R_LABEL)
    ax_s.legend(loc="best", ncols=2 if len(profiles) > 4 else 1)
    save(fig, path)


def plot_accreted_mass(series, snapshots_points, xlabel, m0, path):
    """Accreted mass / M_0 over time: diagnostics.csv (line) and the snapshots' Header AccretedMass (dots)."""
    fig, ax = new_figure(COLUMN)
    if series is not None:
        ax.plot(series[0], series[1] / m0, color="tab:blue", label="diagnostics.csv")
    if snapshots_points is not None:
        ax.plot(snapshots_points[0], snapshots_points[1] / m0, ls="none", marker="o", color="tab:red",
                label="snapshots (Header AccretedMass)")
    ax.set(xlabel=xlabel, ylabel=r"accreted mass / $M_{\rm disc,0}$")
    ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 3))
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left")
    save(fig, path)
