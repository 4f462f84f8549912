"""Particle positions of an sphdisk snapshot relative to the central mass (docs/formats.md, "Snapshot files").

Coordinates in a file lie in [0, BoxSize]^3 with the central mass at Header/PointMassPosition, as yt's
SWIFT reader needs; files without that attribute (older ones, hand-made initial conditions) hold
positions relative to the central mass already. Every reader of Coordinates goes through here.
"""
import numpy as np


def point_mass_position(f):
    """Header/PointMassPosition of an open h5py file (3 values), zeros where absent."""
    header = f["Header"] if "Header" in f else None
    if header is None or "PointMassPosition" not in header.attrs:
        return np.zeros(3)
    return np.asarray(header.attrs["PointMassPosition"], dtype=float).reshape(3)


def positions(f, columns=3):
    """PartType0/Coordinates minus the central mass's position, the first `columns` columns."""
    x = np.asarray(f["PartType0/Coordinates"][:], dtype=float)
    x = x.reshape(len(x), -1)
    return (x - point_mass_position(f)[: x.shape[1]])[:, :columns]
