#!/usr/bin/python3
"""Check that yt.load(path), with no other arguments, reads an sphdisk snapshot right (plain script, no pytest).

    /usr/bin/python3 tests/python/test_yt_load.py [SNAPSHOT.hdf5]

Without SNAPSHOT a synthetic one is made with tools/make_test_run.py. Checks: yt picks its SWIFT
frontend; the code units are the file's /Units (length, mass, time) and the time is Time in them; the
domain is [0, BoxSize]^3 and holds every particle, which ds.all_data() and its derived quantities
count; the gas fields equal what h5py reads; a sphere around Header/PointMassPosition selects the
particles near the central mass; and the projection of ("gas", "density") along z over the whole
domain integrates (sum of pixel value x pixel area) to the particles' total mass.
Prints each check; exits 1 if any failed.

What yt (4.1) needs of the file (docs/formats.md, "Snapshot files"): Header/Code "SWIFT" as a
fixed-length string (this selects the SWIFT frontend; the Gadget one would ignore /Units and take
kpc), BoxSize as 3 values (the domain is [0, BoxSize]), Dimension 3 (with 2 yt 4.1 fails to build
its particle index), Time; /Units with SWIFT's names ("Unit length in cgs (U_L)", ...);
RuntimePars/PeriodicBoundariesOn; Policy/"cosmological integration"; groups Parameters,
HydroScheme and SubgridScheme.
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

# (on-disk dataset, yt field names to read, code unit); yt's SPH frontends call Masses "Mass".
FIELDS = [
    ("Coordinates", ["Coordinates", "particle_position"], "code_length"),
    ("Velocities", ["Velocities", "particle_velocity"], "code_velocity"),
    ("Masses", ["Mass", "particle_mass"], "code_mass"),
    ("Density", ["Density", "density"], "code_mass/code_length**3"),
    ("SmoothingLength", ["SmoothingLength", "smoothing_length"], "code_length"),
    ("ParticleIDs", ["ParticleIDs", "particle_index"], ""),
]
UNITS = [("length_unit", "UnitLength_in_cm", "cm"), ("mass_unit", "UnitMass_in_g", "g"),
         ("time_unit", "UnitTime_in_s", "s")]
PROJECTION_PIXELS = 512
PROJECTION_RTOL = 1e-4  # measured 1.1e-5 (yt's tabulated column kernel), alike at 256-1024 pixels and 2,000-20,000 particles

check = Checks()


def read_raw(path):
    """Particle count, datasets sorted by ParticleIDs, /Units and /Header attributes."""
    with h5py.File(path, "r") as f:
        n = int(f["Header"].attrs["NumPart_ThisFile"][0])
        gas = f["PartType0"]
        order = np.argsort(gas["ParticleIDs"][:], kind="stable")
        data = {name: gas[name][:][order] for name, _, _ in FIELDS if name in gas}
        units = {k: float(v) for k, v in f["Units"].attrs.items()} if "Units" in f else {}
        header = dict(f["Header"].attrs)
    return n, data, units, header


def tolerance(dtype):
    return 0.0 if np.dtype(dtype).kind in "iu" else 4 * np.finfo(dtype).eps


def check_recognised(ds):
    from yt.frontends.swift.api import SwiftDataset
    check(isinstance(ds, SwiftDataset), f"yt.load(path) recognises the file as {type(ds).__name__} (SWIFT)")
    ds.index  # builds the index and detects the on-disk particle types
    check("PartType0" in ds.particle_types_raw, f"particle type PartType0 present ({ds.particle_types_raw})")
    check(not ds.cosmological_simulation, "yt treats it as non-cosmological")


def check_units(ds, units, header):
    """The code units are the file's /Units, without unit_base."""
    if not check(bool(units), "/Units present"):
        return
    for attr, key, unit in UNITS:
        got = float(getattr(ds, attr).to_value(unit))
        check(got == units[key], f"ds.{attr} = {got:.6g} {unit} = /Units {key}")
    t_s = float(ds.current_time.to_value("s"))
    want = float(header["Time"]) * units["UnitTime_in_s"]
    check(np.isclose(t_s, want, rtol=1e-12), f"current_time = {t_s:.6g} s = Time x UnitTime_in_s ({want:.6g} s)")


def check_domain(ds, n, raw, header):
    """The domain is [0, BoxSize]^3 and holds every particle with its kernel (2 h)."""
    box = np.asarray(header["BoxSize"], dtype=float).reshape(-1)
    left, right = ds.domain_left_edge.to_value("code_length"), ds.domain_right_edge.to_value("code_length")
    check(np.array_equal(left, np.zeros(3)) and np.array_equal(right, box * np.ones(3)),
          f"domain [{left.tolist()}, {right.tolist()}] = [0, BoxSize]")
    x, h = raw["Coordinates"], raw["SmoothingLength"][:, None]
    check(bool(np.all(x - 2 * h >= left) and np.all(x + 2 * h <= right)), "every particle's kernel lies in the domain")
    centre = np.asarray(header.get("PointMassPosition", np.zeros(3)), dtype=float)
    check(np.array_equal(centre, right / 2), f"PointMassPosition {centre.tolist()} is the domain centre")
    ad = ds.all_data()
    got = len(ad["PartType0", "ParticleIDs"])
    check(got == n, f"ds.all_data() holds every particle ({got} of {n})")
    count = int(ad.quantities.total_quantity(("PartType0", "particle_ones")))
    check(count == n, f"ad.quantities.total_quantity particle_ones = {count} = N")
    mass = float(ad.quantities.total_quantity(("gas", "mass")).to_value("code_mass"))
    want = float(np.sum(raw["Masses"]))
    check(np.isclose(mass, want, rtol=1e-12), f"ad.quantities total gas mass {mass:.6g} = sum of Masses ({want:.6g})")


def check_fields(ds, n, raw):
    ad = ds.all_data()
    order = np.argsort(np.asarray(ad["PartType0", "ParticleIDs"]), kind="stable")
    for name, yt_names, unit in FIELDS:
        if not check(name in raw, f"{name} in the snapshot"):
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


def check_sphere(ds, raw, header):
    """A sphere around the central mass, in the file's own coordinates, selects the particles near it."""
    centre = np.asarray(header["PointMassPosition"], dtype=float)
    r = np.linalg.norm(raw["Coordinates"] - centre, axis=1)
    radius = float(np.median(r))
    inside = int(np.sum(r < radius))
    reach = int(np.sum(r < radius + 2 * raw["SmoothingLength"].max()))
    got = len(ds.sphere(ds.arr(centre, "code_length"), (radius, "code_length"))["PartType0", "Mass"])
    check(inside <= got <= reach, f"sphere of radius {radius:.3g} around PointMassPosition selects {got} particles "
                                  f"({inside} centres inside, {reach} within reach of their kernels)")


def check_projection(ds, raw):
    """Column density along z over the whole domain: sum of pixel value x pixel area = total mass."""
    proj = ds.proj(("gas", "density"), "z")
    frb = proj.to_frb(ds.domain_width[0], PROJECTION_PIXELS, height=ds.domain_width[1])
    column = frb["gas", "density"].to_value("code_mass/code_length**2")
    pixel_area = float(ds.domain_width[0].to_value("code_length") * ds.domain_width[1].to_value("code_length"))
    pixel_area /= PROJECTION_PIXELS**2
    got = float(column.sum()) * pixel_area
    want = float(np.sum(raw["Masses"]))
    check(abs(got / want - 1) < PROJECTION_RTOL,
          f"projection of (gas, density) along z: {PROJECTION_PIXELS}^2 pixels integrate to {got:.8g}, "
          f"total mass {want:.8g} (relative difference {got / want - 1:.1e}, tolerance {PROJECTION_RTOL:.0e})")


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
    n, raw, units, header = read_raw(path)
    ds = yt.load(path)
    check_recognised(ds)
    check_units(ds, units, header)
    check_domain(ds, n, raw, header)
    check_fields(ds, n, raw)
    check_sphere(ds, raw, header)
    check_projection(ds, raw)


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
