#!/usr/bin/python3
"""SPLASH reads an sphdisk snapshot through tools/snapshot_to_splash.py (plain script, no pytest).

    /usr/bin/python3 tests/python/test_splash.py SNAPSHOT.hdf5

Debian's splash is built without HDF5, so the snapshot is converted to its column format first.
Checks: splash finds every particle and the 2D positions, velocities, mass, smoothing length and
density columns by their names, and renders the column density to a PNG without a terminal.
Prints each check; exits 1 if any failed.
"""
import os
import re
import subprocess
import sys
import tempfile

import h5py
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checklist import Checks  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
CONVERT = os.path.join(ROOT, "tools", "snapshot_to_splash.py")

check = Checks()


def main(snapshot):
    with h5py.File(snapshot, "r") as f:
        n = int(f["Header"].attrs["NumPart_ThisFile"][0])
    with tempfile.TemporaryDirectory() as tmp:
        table = os.path.join(tmp, "snap.ascii")
        subprocess.run([sys.executable, CONVERT, snapshot, table], check=True, stdout=subprocess.DEVNULL)
        image = os.path.join(tmp, "sigma.png")
        p = subprocess.run(["splash", "-f", "ascii", table, "-x", "1", "-y", "2", "-r", "7", "-dev", image],
                           stdin=subprocess.DEVNULL, capture_output=True, text=True, cwd=tmp, timeout=120)
        out = p.stdout + p.stderr
        check(p.returncode == 0, f"splash exits 0 (exit {p.returncode})")
        m = re.search(r"npts\s*=\s*(\d+),\s*ncols\s*=\s*(\d+)", out)
        check(m is not None and int(m.group(1)) == n and int(m.group(2)) == 7,
              f"splash reads {n} particles in 7 columns ({m.group(0) if m else 'no npts line'})")
        check("Assuming 2 dimensions, coords in cols  1 to  2" in out, "splash takes columns 1-2 as the 2D positions")
        check(re.search(r"density in column\s+7, mass in\s+5, h in\s+6", out) is not None,
              "splash finds density, mass and smoothing length by their names")
        check("velocity in cols  3 to  4" in out, "splash finds the velocities")
        check(os.path.isfile(image) and os.path.getsize(image) > 1000, "splash renders the column density to a PNG")
    return check.exit_code("splash")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
