#!/usr/bin/python3
"""Effective viscous time of a ring snapshot: the tau* whose analytic profile fits the binned mass
surface density best (L1 over 50 bins, 0.05-2.05 r0, as `sphdisk analyze`).

Usage: fit_viscous_time.py SNAPSHOT.hdf5 [...]

tau*/tau < 1 means the ring spread too slowly (effective viscosity too low), > 1 too fast; the L1
that remains at tau* is error in the shape of the profile (noise, clumping), not in the viscosity.
The analytic solution (P98 eq. 11, Lynden-Bell & Pringle) is evaluated here independently of the
C++ code, with scipy's exponentially scaled Bessel function.
"""
import os
import sys

import h5py
import numpy as np
from scipy.special import ive

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
from snapshot_positions import positions  # noqa: E402  (Coordinates relative to the central mass)

EDGES = np.linspace(0.05, 2.05, 51)


def sigma(x, tau, mass):
    # Sigma = m / (pi r0^2 tau) x^-1/4 exp(-(1 + x^2) / tau) I_1/4(2x / tau), with I = ive * exp(z)
    return mass / np.pi / tau * x**-0.25 * np.exp(-((1 - x) ** 2) / tau) * ive(0.25, 2 * x / tau)


def annulus_means(tau, mass):
    out = []
    for a, b in zip(EDGES[:-1], EDGES[1:]):
        x = np.linspace(a, b, 201)
        out.append(np.trapz(sigma(x, tau, mass) * 2 * np.pi * x, x) / (np.pi * (b * b - a * a)))
    return np.array(out)


def fit(path):
    """(tau, L1 at tau, best-fit tau*, L1 at tau*) of one snapshot."""
    with h5py.File(path) as s:
        x = positions(s)
        m = s["PartType0/Masses"][:]
        tau = s["Header"].attrs["ViscousTime"]
        mass = s["Header"].attrs["DiskMass"]
    r = np.hypot(x[:, 0], x[:, 1])
    binned, _ = np.histogram(r, bins=EDGES, weights=m)
    binned /= np.pi * (EDGES[1:] ** 2 - EDGES[:-1] ** 2)

    def l1(t):
        a = annulus_means(t, mass)
        return np.abs(binned - a).sum() / a.sum()

    best = min(tau * np.linspace(0.5, 1.5, 201), key=l1)  # (the range and step of `sphdisk analyze`)
    return tau, l1(tau), best, l1(best)


def main():
    for path in sys.argv[1:]:
        tau, l1, best, l1_best = fit(path)
        print(f"{path}: tau {tau:.4f}  L1 {l1:.4f}  best-fit tau* {best:.4f} (tau*/tau {best / tau:.3f}), L1 there {l1_best:.4f}")


if __name__ == "__main__":
    main()
