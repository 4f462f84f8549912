#!/usr/bin/python3
"""Radial slope of ln Sigma that the consistent viscous force sees (docs/validation.md): at 4,000
random particles with 0.75 < r < 1.25 it forms the linear-exact SPH gradient of ln rho from the
snapshot's summation densities, sum_j V_j (ln rho_j - ln rho_i) grad W_ij M^-1 (cubic spline, pair-
averaged kernel gradient, as the code), and the same from the analytic Sigma at the particles, and
prints each one's projection on the analytic d ln Sigma / dr (1 = unbiased).

Usage: density_slope.py SNAPSHOT.hdf5 [...]
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


def dw_over_r(d, h):
    q = d / h
    dw = np.where(q < 1, -3 * q + 2.25 * q * q, np.where(q < 2, -0.75 * (2 - q) ** 2, 0.0))
    return NORM / h**3 * dw / np.maximum(d, 1e-300)


def slopes(path, sample=4000):
    with h5py.File(path) as f:
        x = positions(f, 2)
        m = f["PartType0/Masses"][:]
        rho = f["PartType0/Density"][:]
        h = f["PartType0/SmoothingLength"][:]
        mass, tau = f["Header"].attrs["DiskMass"], f["Header"].attrs["ViscousTime"]
    r = np.hypot(x[:, 0], x[:, 1])
    eps = 1e-6
    exact = (np.log(sigma(r + eps, tau, mass)) - np.log(sigma(r - eps, tau, mass))) / (2 * eps)
    fields = {"summation density": np.log(rho), "analytic Sigma": np.log(sigma(r, tau, mass))}
    pick = np.random.default_rng(0).choice(np.where(np.abs(r - 1) < 0.25)[0], sample, replace=False)
    tree, volume = cKDTree(x), m / rho
    est = {k: [] for k in fields}
    for i in pick:
        js = np.array(tree.query_ball_point(x[i], 2 * h.max()))
        js = js[js != i]
        dx = x[i] - x[js]
        d = np.hypot(dx[:, 0], dx[:, 1])
        F = 0.5 * (dw_over_r(d, h[i]) + dw_over_r(d, h[js]))
        js, dx, F = js[F != 0], dx[F != 0], F[F != 0]
        M = -(volume[js, None, None] * F[:, None, None] * dx[:, :, None] * dx[:, None, :]).sum(0)
        C, e_r = np.linalg.inv(M), x[i] / r[i]
        for k, l in fields.items():
            grad = (volume[js, None] * (l[js] - l[i])[:, None] * dx * F[:, None]).sum(0) @ C
            est[k].append(grad @ e_r)
    ref = exact[pick]
    return {k: (np.array(v) * ref).sum() / (ref * ref).sum() for k, v in est.items()}


def main():
    for path in sys.argv[1:]:
        s = slopes(path)
        print(f"{path}: d ln Sigma / dr estimated / analytic: " + ", ".join(f"{k} {v:.3f}" for k, v in s.items()))


if __name__ == "__main__":
    main()
