#!/usr/bin/python3
"""Writes an sphdisk snapshot as the column file SPLASH reads (`splash -f ascii FILE`).

    /usr/bin/python3 tools/snapshot_to_splash.py SNAPSHOT.hdf5 [OUT.ascii]

Debian's splash (3.6) is built without HDF5, so it cannot open the snapshots themselves. The columns
are x y [z] vx vy [vz] m h rho, positions relative to the central mass (Coordinates minus
Header/PointMassPosition), in the snapshot's code units; a comment line names them, which splash
uses to label its axes and to find the mass, smoothing length and density columns.
"""
import os
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from snapshot_positions import positions  # noqa: E402


def columns(path):
    """(names, array of columns) of the snapshot's particles."""
    with h5py.File(path, "r") as f:
        header = f["Header"].attrs
        dim = int(header.get("SimulationDimension", header.get("Dimension", 3)))
        pos = positions(f)[:, :dim]
        gas = f["PartType0"]
        vel = gas["Velocities"][:][:, :dim]
        data = [pos, vel, gas["Masses"][:], gas["SmoothingLength"][:], gas["Density"][:]]
    axes = "xyz"[:dim]
    names = list(axes) + [f"v{a}" for a in axes] + ["m", "h", "rho"]
    return names, np.column_stack(data)


def main(argv):
    if len(argv) not in (2, 3):
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    out = argv[2] if len(argv) == 3 else os.path.splitext(argv[1])[0] + ".ascii"
    names, data = columns(argv[1])
    with open(out, "w") as fh:
        fh.write("# " + " ".join(names) + "\n")
        np.savetxt(fh, data, fmt="%.17g")
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
