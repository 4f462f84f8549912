#!/usr/bin/python3
"""Whether a locally isothermal power-law disc keeps its equilibrium (docs/validation.md): the annulus
Sigma against Sigma_0 R^-p at the start and at the end, in 16 bins over [R_in, R_out] (the edges'
bins left out of the comparison), and the particles' rms z / H(R) and rms v_z / c_s(R) in three
radial bands, with H = c_s / Omega and c_s = (H/R)_0 R^-q.

Usage: disc_equilibrium.py FIRST.hdf5 LAST.hdf5 [R_in R_out p q H/R disc_mass]
       (defaults: configs/disc_phantom_like.toml's 1 5 1 0.25 0.05 1e-3, code units G = M = 1)
"""
import sys

import h5py
import numpy as np


def load(path):
    with h5py.File(path, "r") as f:
        x = f["PartType0/Coordinates"][:] - f["Header"].attrs["PointMassPosition"]
        return x, f["PartType0/Velocities"][:], f["PartType0/Masses"][:], float(f["Header"].attrs["Time"])


def main():
    if len(sys.argv) not in (3, 9):
        sys.exit(__doc__)
    r_in, r_out, p, q, aspect, mass = [float(a) for a in sys.argv[3:]] or [1.0, 5.0, 1.0, 0.25, 0.05, 1e-3]
    edges = np.linspace(r_in, r_out, 17)
    mid = 0.5 * (edges[1:] + edges[:-1])
    e = 2.0 - p
    norm = np.log(r_out / r_in) if abs(e) < 1e-12 else (r_out**e - r_in**e) / e
    analytic = mass / (2 * np.pi * norm) * mid**-p
    inner = (mid > edges[2]) & (mid < edges[-3])
    profiles = []
    for path in sys.argv[1:3]:
        x, v, m, t = load(path)
        R = np.hypot(x[:, 0], x[:, 1])
        M, _ = np.histogram(R, edges, weights=m)
        sigma = M / (np.pi * (edges[1:] ** 2 - edges[:-1] ** 2))
        profiles.append(sigma)
        c = aspect * R**-q
        H = c * R**1.5
        print(f"{path}: t = {t:.4g}; Sigma / Sigma_0 R^-p between {edges[2]:.3g} and {edges[-3]:.3g}: "
              + " ".join(f"{s:.3f}" for s in sigma[inner] / analytic[inner]))
        bands = np.linspace(edges[2], edges[-3], 4)
        for lo, hi in zip(bands[:-1], bands[1:]):
            s = (R > lo) & (R < hi)
            print(f"  R {lo:.2f}-{hi:.2f}: rms z / H {np.sqrt(np.mean((x[s, 2] / H[s]) ** 2)):.3f}, "
                  f"rms v_z / c_s {np.sqrt(np.mean((v[s, 2] / c[s]) ** 2)):.3f}")
    print(f"mean |Sigma_last / Sigma_first - 1| over those bins: {np.mean(np.abs(profiles[1][inner] / profiles[0][inner] - 1)):.4f}")


if __name__ == "__main__":
    main()
