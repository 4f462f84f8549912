#!/usr/bin/python3
"""Median smoothing length of a ring snapshot's particles in the core (|r / r0 - 1| < 0.1), in r0:
the h of docs/validation.md's table of the particles' SPH Sigma against h / H.

Usage: bench/core_smoothing_length.py SNAPSHOT.hdf5 [SNAPSHOT.hdf5 ...]
"""
import os
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
from snapshot_positions import positions  # noqa: E402  (Coordinates relative to the central mass)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for path in sys.argv[1:]:
        with h5py.File(path, "r") as f:
            r0 = float(f["Header"].attrs["RingRadius"])
            x = positions(f, 2)
            h = f["PartType0/SmoothingLength"][:]
        r = np.hypot(x[:, 0], x[:, 1]) / r0
        core = np.abs(r - 1.0) < 0.1
        print(f"{path}: median h in the core {np.median(h[core]) / r0:.5f} r0 ({core.sum()} particles)")


if __name__ == "__main__":
    main()
