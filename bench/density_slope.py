#!/usr/bin/python3
"""Radial slope of ln Sigma that the consistent viscous force sees (docs/validation.md).

Default: at 4,000 random particles with 0.75 < r < 1.25 it forms the linear-exact SPH gradient of
ln rho from the snapshot's summation densities, sum_j V_j (ln rho_j - ln rho_i) grad W_ij M^-1
(cubic spline, pair-averaged kernel gradient, as the code), and the same from the analytic Sigma at
the particles, and prints each one's projection on the analytic d ln Sigma / dr (1 = unbiased).

--bins: the same per bin of z = (r - r0) / sqrt(tau / 2) (the ring's tails are |z| > 2), up to 800
particles a bin, beside a third estimate, the kernel derivative of the density without the self
term, sum_j m_j grad W(r_ij, h_i) / sum_j m_j W(r_ij, h_i) (j != i, the particle's own h). Each
column prints projection / rms scatter (the scatter of estimate - analytic over the rms analytic
slope of the bin).

Usage: density_slope.py [--bins] SNAPSHOT.hdf5 [...]
"""
import os
import sys

import h5py
import numpy as np
from scipy.spatial import cKDTree

from fit_viscous_time import sigma

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
from snapshot_positions import positions  # noqa: E402  (Coordinates relative to the central mass)

NORM = 10 / (7 * np.pi)  # 2D cubic spline
Z_BINS = [(-9, -3), (-3, -2), (-2, -1), (-1, 0), (0, 1), (1, 2), (2, 3), (3, 9)]


def kernel(d, h):
    q = d / h
    return NORM / h**2 * np.where(q < 1, 1 - 1.5 * q * q + 0.75 * q**3, np.where(q < 2, 0.25 * (2 - q) ** 3, 0.0))


def dw_over_r(d, h):
    q = d / h
    dw = np.where(q < 1, -3 * q + 2.25 * q * q, np.where(q < 2, -0.75 * (2 - q) ** 2, 0.0))
    return NORM / h**3 * dw / np.maximum(d, 1e-300)


def load(path):
    with h5py.File(path) as f:
        x = positions(f, 2)
        snap = {"x": x, "m": f["PartType0/Masses"][:], "rho": f["PartType0/Density"][:],
                "h": f["PartType0/SmoothingLength"][:], "mass": f["Header"].attrs["DiskMass"],
                "tau": f["Header"].attrs["ViscousTime"]}
    snap["r"] = np.hypot(x[:, 0], x[:, 1])
    return snap


def estimates(s, i, tree, reach, kernel_derivative):
    """Particle i's radial slopes of ln rho: linear-exact differences of the summation densities and
    of the analytic Sigma, and (optionally) the kernel derivative without the self term."""
    x, m, h, vol = s["x"], s["m"], s["h"], s["m"] / s["rho"]
    js = np.array(tree.query_ball_point(x[i], reach))
    js = js[js != i]
    dx = x[i] - x[js]
    d = np.hypot(dx[:, 0], dx[:, 1])
    F_own = dw_over_r(d, h[i])
    F = 0.5 * (F_own + dw_over_r(d, h[js]))
    keep = F != 0
    js, dx, d, F, F_own = js[keep], dx[keep], d[keep], F[keep], F_own[keep]
    M = -(vol[js, None, None] * F[:, None, None] * dx[:, :, None] * dx[:, None, :]).sum(0)
    C, e_r = np.linalg.inv(M), x[i] / s["r"][i]
    out = {}
    for k, l in (("summation differences", np.log(s["rho"])), ("analytic Sigma differences", s["ln_sigma"])):
        out[k] = ((vol[js, None] * (l[js] - l[i])[:, None] * dx * F[:, None]).sum(0) @ C) @ e_r
    if kernel_derivative:  # grad_i W_ij = (x_i - x_j) F
        out["kernel derivative, no self term"] = (m[js, None] * dx * F_own[:, None]).sum(0) @ e_r / (m[js] * kernel(d, h[i])).sum()
    return out


def projections(s, pick, exact, kernel_derivative):
    tree = cKDTree(s["x"])
    est = {}
    for i in pick:
        reach = 2 * (s["h"].max() if not kernel_derivative else 3 * s["h"][i])
        for k, v in estimates(s, i, tree, reach, kernel_derivative).items():
            est.setdefault(k, []).append(v)
    ref = exact[pick]
    return {k: ((np.array(v) * ref).sum() / (ref * ref).sum(), np.std(np.array(v) - ref) / np.sqrt(np.mean(ref * ref)))
            for k, v in est.items()}


def main():
    args = sys.argv[1:]
    by_bins = "--bins" in args
    for path in [a for a in args if a != "--bins"]:
        s = load(path)
        r, tau, mass, eps = s["r"], s["tau"], s["mass"], 1e-6
        s["ln_sigma"] = np.log(sigma(r, tau, mass))
        exact = (np.log(sigma(r + eps, tau, mass)) - np.log(sigma(r - eps, tau, mass))) / (2 * eps)
        rng = np.random.default_rng(0)
        if not by_bins:
            pick = rng.choice(np.where(np.abs(r - 1) < 0.25)[0], 4000, replace=False)
            p = projections(s, pick, exact, False)
            print(f"{path}: d ln Sigma / dr estimated / analytic: " + ", ".join(f"{k.split()[0]} {v[0]:.3f}" for k, v in p.items()))
            continue
        z = (r - 1) / np.sqrt(tau / 2)
        print(f"{path}: tau {tau:g}, {len(r)} particles; per bin of z: projection / rms scatter")
        for lo, hi in Z_BINS:
            idx = np.where((z >= lo) & (z < hi))[0]
            if len(idx) == 0:
                continue
            pick = rng.choice(idx, min(800, len(idx)), replace=False)
            p = projections(s, pick, exact, True)
            print(f"  z {lo:+d}..{hi:+d} ({len(idx):6d} particles, h / sqrt(tau/2) {np.median(s['h'][pick]) / np.sqrt(tau / 2):.2f}): "
                  + "; ".join(f"{k} {v[0]:.2f} / {v[1]:.2f}" for k, v in p.items()))


if __name__ == "__main__":
    main()
