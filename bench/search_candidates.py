#!/usr/bin/python3
"""What a 3D search scans (docs/performance.md, "Three dimensions"): for each particle of a snapshot,
the particles in the cells within reach ceil(2h / cell) of its cell (whole cells, cell = FACTOR x the
median h, as kCellOverMedianH in src/evaluate/cells_and_tiles.hpp) against its neighbours within 2h
(brute force by a k-d tree), overall and by cylindrical radius about the point mass.

Usage: bench/search_candidates.py SNAPSHOT.hdf5 [FACTOR ...]   (FACTOR default 2.1)
"""
import sys

import h5py
import numpy as np
from scipy.spatial import cKDTree


def main():
    f = h5py.File(sys.argv[1], "r")
    x = f["PartType0/Coordinates"][:]
    h = f["PartType0/SmoothingLength"][:]
    centre = f["Header"].attrs["PointMassPosition"]
    if x.shape[1] != 3:
        sys.exit("search_candidates: a 3D snapshot is needed")
    radius = 2 * h
    neighbours = np.array([len(l) for l in cKDTree(x).query_ball_point(x, radius)])
    R = np.hypot(x[:, 0] - centre[0], x[:, 1] - centre[1])
    for factor in [float(a) for a in sys.argv[2:]] or [2.1]:
        cell = factor * np.median(h)
        c = np.floor((x - x.min(0)) / cell).astype(int)
        dims = c.max(0) + 1
        grid = np.zeros(dims, int)
        np.add.at(grid, tuple(c.T), 1)
        P = np.zeros(dims + 1, int)  # prefix sums: the count of any box of cells
        P[1:, 1:, 1:] = grid.cumsum(0).cumsum(1).cumsum(2)
        reach = np.ceil(radius / cell).astype(int)
        a = np.maximum(c - reach[:, None], 0)
        b = np.minimum(c + reach[:, None], dims - 1) + 1
        cand = (P[b[:, 0], b[:, 1], b[:, 2]] - P[a[:, 0], b[:, 1], b[:, 2]] - P[b[:, 0], a[:, 1], b[:, 2]]
                - P[b[:, 0], b[:, 1], a[:, 2]] + P[a[:, 0], a[:, 1], b[:, 2]] + P[a[:, 0], b[:, 1], a[:, 2]]
                + P[b[:, 0], a[:, 1], a[:, 2]] - P[a[:, 0], a[:, 1], a[:, 2]])
        print(f"cell {factor} x median h: reach counts {np.bincount(reach).tolist()}; candidates per particle "
              f"{cand.mean():.0f}, neighbours {neighbours.mean():.1f}, {cand.sum() / neighbours.sum():.1f} per neighbour")
        for lo, hi in [(0, 1.5), (1.5, 2), (2, 3), (3, 4), (4, 6)]:
            m = (R >= lo) & (R < hi)
            if m.any():
                print(f"  R {lo}-{hi}: {m.mean() * 100:.0f}% of particles, {cand[m].sum() / neighbours[m].sum():.1f} candidates per neighbour")


if __name__ == "__main__":
    main()
