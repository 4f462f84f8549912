#!/usr/bin/python3
"""Conservation budgets of a ring run (docs/validation.md): mass, angular momentum about the point
mass (particles + accreted) from diagnostics.csv between the first and the last row, and in each
snapshot the net SPH force sum m a against sum m |a| (linear momentum: exactly zero with the
conservative form of eq. 6, the discretisation error with the consistent one). Needs snapshots
whose Acceleration is the SPH part alone (integrator.scheme = "block" or "respa").

Usage: ring_budgets.py RUN_DIR [...]
"""
import csv
import pathlib
import sys

import h5py
import numpy as np


def main():
    for d in map(pathlib.Path, sys.argv[1:]):
        rows = list(csv.DictReader(open(d / "diagnostics.csv")))
        first, last = rows[0], rows[-1]
        mass = [float(r["mass"]) + float(r["accreted_mass"]) for r in (first, last)]
        ang = [float(r["angular_momentum"]) + float(r["accreted_angular_momentum"]) for r in (first, last)]
        print(f"{d}: mass change {mass[1] / mass[0] - 1:.2e}, angular momentum change {ang[1] / ang[0] - 1:.2e} "
              f"(tau {float(first['tau']):.3f} -> {float(last['tau']):.3f})")
        for snap in sorted(d.glob("snapshot_*.hdf5"))[1:]:
            with h5py.File(snap) as s:
                a = s["PartType0/Acceleration"][:, :2]
                m = s["PartType0/Masses"][:]
                tau = s["Header"].attrs["ViscousTime"]
            net = np.abs((m[:, None] * a).sum(0)).sum()
            scale = (m * np.hypot(a[:, 0], a[:, 1])).sum()
            print(f"  {snap.name} (tau {tau:.3f}): |sum m a| / sum m |a| = {net / scale:.2e}")


if __name__ == "__main__":
    main()
