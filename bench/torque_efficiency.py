#!/usr/bin/python3
"""Viscous torque of a ring snapshot against the continuum's (docs/validation.md, "Why the ring
spread too slowly").

Usage: torque_efficiency.py SNAPSHOT.hdf5 [...]

For 20 annuli over 0.5-1.5 r0 it sums the particles' torques m r a_phi (the point mass's gravity is
central, so a_phi is the SPH force alone) and compares them with the continuum torque on the same
annuli, G(r_out) - G(r_in) with G = -3 pi nu Sigma r^1/2 (Kepler rotation, eqs. 10-12 of P98), for
the analytic Sigma at the viscous time tau* that best fits the snapshot's binned mass (the profile
the particles actually have). Prints the projection sum T C / sum C^2: 1 when the SPH torque is the
continuum's, below 1 when the ring spreads too slowly for its own profile. The particles' own
velocities set the SPH torque; the same positions with Kepler velocities (bench/kepler_velocities.py,
then one step of `sphdisk run` from them) separate what the positions do from what the velocities do.
"""
import os
import sys

import h5py
import numpy as np

from fit_viscous_time import fit, sigma

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
from snapshot_positions import positions  # noqa: E402  (Coordinates relative to the central mass)

EDGES = np.linspace(0.5, 1.5, 21)


def efficiency(path):
    with h5py.File(path) as s:
        x = positions(s, 2)
        a = s["PartType0/Acceleration"][:, :2]
        m = s["PartType0/Masses"][:]
        nu = s["Header"].attrs["KinematicViscosity"]
        mass = s["Header"].attrs["DiskMass"]
    _, _, tau_fit, _ = fit(path)
    r = np.hypot(x[:, 0], x[:, 1])
    e_phi = np.stack([-x[:, 1], x[:, 0]], 1) / r[:, None]
    torque, _ = np.histogram(r, EDGES, weights=m * r * (a * e_phi).sum(1))
    continuum = np.diff(-3 * np.pi * nu * sigma(EDGES, tau_fit, mass) * np.sqrt(EDGES))
    return tau_fit, (torque * continuum).sum() / (continuum * continuum).sum()


def main():
    for path in sys.argv[1:]:
        tau_fit, eff = efficiency(path)
        print(f"{path}: tau* {tau_fit:.4f}  SPH torque / continuum torque {eff:.3f}")


if __name__ == "__main__":
    main()
