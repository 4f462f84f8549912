#!/usr/bin/env python3
"""Two kernel-scale biases of a ring snapshot that slow the viscous spreading (docs/validation.md):
  1. the summation density against the analytic Sigma (median rho/Sigma for 0.85 < r < 1.15): the
     self term m W(0) and particle clumping make rho, and with it 1/rho in eq. 6, biased;
  2. the shear of the particles' own velocity field measured with the linear-exact (moment-corrected)
     SPH gradient, against the Keplerian r dOmega/dr = -1.5 Omega (mean over particles with
     0.8 < r < 1.2): below 1 when neighbours move more alike than Kepler orbits would.
Usage: bench/kernel_scale_bias.py SNAPSHOT [SNAPSHOT ...]   (cubic spline kernel, gather with own h)"""
import os
import sys
import h5py
import numpy as np
from scipy.spatial import cKDTree
from scipy.special import ive

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
from snapshot_positions import positions  # noqa: E402  (Coordinates relative to the central mass)


def dw_dq(q):  # cubic spline w'(q), 2D normalisation 10/(7 pi h^2) applied by the caller
    return np.where(q < 1, -3 * q + 2.25 * q * q, np.where(q < 2, -0.75 * (2 - q) ** 2, 0.0))


def analyse(path, sample=6000):
    f = h5py.File(path, "r")
    header = dict(f["Header"].attrs)
    x = positions(f, 2)
    v = f["PartType0/Velocities"][:, :2]
    m = f["PartType0/Masses"][:]
    rho = f["PartType0/Density"][:]
    h = f["PartType0/SmoothingLength"][:]
    tau, disc_mass = header["ViscousTime"], header["DiskMass"]
    r = np.hypot(x[:, 0], x[:, 1])
    sigma = disc_mass / (np.pi * tau * r**0.25) * np.exp(-(1 - r) ** 2 / tau) * ive(0.25, 2 * r / tau)
    band = (r > 0.85) & (r < 1.15)
    density_bias = np.median(rho[band] / sigma[band])
    tree = cKDTree(x)
    ratios = []
    for i in np.where((r > 0.8) & (r < 1.2))[0][:sample]:
        js = np.array([j for j in tree.query_ball_point(x[i], 2 * h[i]) if j != i])
        d = x[i] - x[js]
        q = np.hypot(d[:, 0], d[:, 1]) / h[i]
        grad = (10 / (7 * np.pi * h[i] ** 3) * dw_dq(q) / (q * h[i]))[:, None] * d  # grad_i W_ij
        vol = m[js] / rho[js]
        V = np.einsum("j,ja,jb->ab", vol, v[js] - v[i], grad)   # eq. 8
        M = -np.einsum("j,ja,jb->ab", vol, d, grad)            # moment matrix (identity ideally)
        G = V @ np.linalg.inv(M)                               # linear-exact gradient dv_a/dx_b
        c, s = x[i] / r[i]
        R = np.array([[c, s], [-s, c]])                        # to (r, phi)
        Gp = R @ G @ R.T
        ratios.append((Gp[1, 0] + Gp[0, 1]) / (-1.5 * r[i] ** -1.5))
    return tau, density_bias, float(np.mean(ratios))


if __name__ == "__main__":
    print("snapshot | tau | median rho/Sigma_analytic | mean shear / Kepler")
    for p in sys.argv[1:]:
        tau, bias, shear = analyse(p)
        print(f"{p} | {tau:.3f} | {bias:.3f} | {shear:.3f}")
