#!/usr/bin/python3
"""Check that yt reads an sphdisk snapshot as a GADGET-style HDF5 dataset (plain script, no pytest).

    /usr/bin/python3 tests/python/test_yt_load.py [SNAPSHOT.hdf5]

Without SNAPSHOT a synthetic one is made with tools/make_test_run.py. Checks: yt.load recognises
the file (Gadget HDF5 frontend), the gas fields read via ds.all_data() have the right particle count
and equal what h5py reads, and loading with unit_base taken from /Units gives the cgs units.
Prints each check; exits 1 if any failed.

What yt (4.1) needs, found by removing attributes one at a time:
- a /Header group and no root group FOF, Group or Subhalo (and no /Config with VORONOI or AMR, no
  /Constants, no PartType0/GFM_* or 11-column Metallicity: those select other frontends);
- Header attributes NumPart_ThisFile, MassTable, Time, BoxSize (non-zero: BoxSize = 0 raises
  ZeroDivisionError) and NumFilesPerSnapshot;
- Header/Code, if present, a fixed-length string: a variable-length one makes yt.load raise
  AttributeError ('str' object has no attribute 'decode'), and it must not be "SWIFT";
- no /Parameters attribute named like a Header attribute (yt merges /Parameters over /Header).
yt ignores /Units for this frontend: pass unit_base (done below) for cgs units; it assumes a periodic
box [0, BoxSize]^3, so pass bounding_box for spatial selections of a disc centred on the origin.
"""
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checklist import Checks  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
MAKE_RUN = os.path.join(ROOT, "tools", "make_test_run.py")

# (on-disk dataset, yt field names to read, code unit)
FIELDS = [
    ("Coordinates", ["Coordinates", "particle_position"], "code_length"),
    ("Velocities", ["Velocities", "particle_velocity"], "code_velocity"),
    ("Masses", ["Masses", "particle_mass"], "code_mass"),
    ("Density", ["Density", "density"], "code_mass/code_length**3"),
    ("SmoothingLength", ["SmoothingLength", "smoothing_length"], "code_length"),
    ("ParticleIDs", ["ParticleIDs", "particle_index"], ""),
]

check = Checks()


def read_raw(path):
    """Particle count, datasets sorted by ParticleIDs, /Units attributes and Header/Time."""
    with h5py.File(path, "r") as f:
        n = int(f["Header"].attrs["NumPart_ThisFile"][0])
        gas = f["PartType0"]
        order = np.argsort(gas["ParticleIDs"][:], kind="stable")
        data = {name: gas[name][:][order] for name, _, _ in FIELDS if name in gas}
        units = {k: float(v) for k, v in f["Units"].attrs.items()} if "Units" in f else {}
        time = float(f["Header"].attrs["Time"])
    return n, data, units, time


def tolerance(dtype):
    return 0.0 if np.dtype(dtype).kind in "iu" else 4 * np.finfo(dtype).eps


def check_recognised(ds):
    from yt.frontends.gadget.api import GadgetHDF5Dataset
    check(isinstance(ds, GadgetHDF5Dataset), f"yt recognises the file as {type(ds).__name__} (Gadget HDF5)")
    ds.index  # builds the index and detects the on-disk particle types
    check("PartType0" in ds.particle_types_raw, f"particle type PartType0 present ({ds.particle_types_raw})")
    check(not ds.cosmological_simulation, "yt treats it as non-cosmological")


def check_fields(ds, n, raw):
    ad = ds.all_data()
    order = np.argsort(np.asarray(ad["PartType0", "ParticleIDs"]), kind="stable")
    for name, yt_names, unit in FIELDS:
        if name not in raw:
            check(False, f"{name} in the snapshot")
            continue
        want = raw[name]
        for yt_name in yt_names:
            arr = ad["PartType0", yt_name]
            got = np.asarray(arr.to_value(unit) if unit else arr)[order]
            if not check(len(got) == n, f"('PartType0', '{yt_name}') has {n} particles (got {len(got)})"):
                continue
            rtol = tolerance(want.dtype)
            same = got.shape == want.shape and np.allclose(got, want, rtol=rtol, atol=0.0)
            check(same, f"('PartType0', '{yt_name}') equals h5py's {name} (rtol {rtol:.1e}, {unit or 'no unit'})")


def check_units(path, units, time, raw):
    """Loading with unit_base from /Units and a bounding box centred on the origin."""
    import yt
    if not check(bool(units), "/Units present for unit_base"):
        return
    extent = 1.01 * float(np.max(np.abs(raw["Coordinates"]))) + float(np.max(raw["SmoothingLength"]))
    box = [[-extent, extent]] * 3
    ds = yt.load(path, unit_base=units, bounding_box=box)
    for attr, key, unit in (("length_unit", "UnitLength_in_cm", "cm"), ("mass_unit", "UnitMass_in_g", "g"),
                            ("velocity_unit", "UnitVelocity_in_cm_per_s", "cm/s")):
        got = float(getattr(ds, attr).to_value(unit))
        check(np.isclose(got, units[key], rtol=1e-12), f"unit_base: ds.{attr} = {got:.6g} {unit} = /Units {key}")
    t_s = float(ds.current_time.to_value("s"))
    want = time * units.get("UnitTime_in_s", units["UnitLength_in_cm"] / units["UnitVelocity_in_cm_per_s"])
    check(np.isclose(t_s, want, rtol=1e-6), f"current_time = {t_s:.6g} s = Time x UnitTime_in_s ({want:.6g} s)")
    x_cm = ds.all_data()["PartType0", "Coordinates"].to_value("cm")
    check(np.isclose(np.abs(x_cm).max(), np.abs(raw["Coordinates"]).max() * units["UnitLength_in_cm"], rtol=1e-12),
          "coordinates in cm = code values x UnitLength_in_cm")
    radius = 0.5 * extent
    r = np.linalg.norm(raw["Coordinates"], axis=1)
    inside = int(np.sum(r < radius))
    got = len(ds.sphere([0.0, 0.0, 0.0], (radius, "code_length"))["PartType0", "Masses"])
    check(inside <= got <= int(np.sum(r < radius + 2 * raw["SmoothingLength"].max())),
          f"sphere of radius {radius:.3g} at the origin selects {got} particles ({inside} centres inside)")


def synthetic_snapshot(tmp):
    res = subprocess.run([sys.executable, MAKE_RUN, os.path.join(tmp, "run"), "--particles", "2000",
                          "--taus", "0.018,0.09"], capture_output=True, text=True)
    if res.returncode != 0:
        sys.exit(f"test_yt_load.py: make_test_run.py failed: {res.stderr.strip()}")
    return os.path.join(tmp, "run", "snapshot_001.hdf5")


def run_checks(path):
    import yt
    yt.set_log_level(40)
    print(f"snapshot: {path} (yt {yt.__version__})")
    n, raw, units, time = read_raw(path)
    ds = yt.load(path)
    check_recognised(ds)
    check_fields(ds, n, raw)
    check_units(path, units, time, raw)


def main(argv):
    if len(argv) > 1:
        print("usage: test_yt_load.py [SNAPSHOT.hdf5]", file=sys.stderr)
        return 2
    if argv:
        if not os.path.isfile(argv[0]):
            print(f"test_yt_load.py: no such file '{argv[0]}'", file=sys.stderr)
            return 2
        run_checks(argv[0])
    else:
        with tempfile.TemporaryDirectory(prefix="sphdisk_yt_test_") as tmp:
            run_checks(synthetic_snapshot(tmp))
    return check.exit_code("yt")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
