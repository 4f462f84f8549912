#!/usr/bin/python3
"""Initial conditions with a snapshot's positions and Kepler velocities (docs/validation.md, "Why
the ring spread too slowly"): evaluated by `sphdisk run` (problem.initial_conditions, run.max_steps
= 1), its SPH torque (bench/torque_efficiency.py) is what the particle positions alone give.

Usage: kepler_velocities.py SNAPSHOT.hdf5 OUT.hdf5
"""
import os
import shutil
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
from snapshot_positions import positions  # noqa: E402  (Coordinates relative to the central mass)


def main():
    src, dst = sys.argv[1], sys.argv[2]
    shutil.copy(src, dst)
    with h5py.File(dst, "r+") as f:
        x = positions(f)
        v = f["PartType0/Velocities"][:]
        r = np.hypot(x[:, 0], x[:, 1])
        v[:, 0] = -x[:, 1] / r * r**-0.5  # G M = 1: v = r^-1/2 along e_phi
        v[:, 1] = x[:, 0] / r * r**-0.5
        f["PartType0/Velocities"][:] = v


if __name__ == "__main__":
    main()
