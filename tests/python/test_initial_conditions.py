#!/usr/bin/python3
"""Initial conditions from a user's HDF5 file (made here with h5py, as users build set-ups in Python).

Usage: test_initial_conditions.py SPHDISK

A minimal file (PartType0 with Coordinates, Velocities, Masses, ParticleIDs; /Header Time; /Units in
cgs with a length unit of 2 solar radii) is run for a short time; the output must keep every
particle ID and mass, convert units (positions in the run's code units are twice the file's) and
start at the file's time.
"""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
sys.dont_write_bytecode = True  # no tools/__pycache__ in the work tree
from checklist import summarise  # noqa: E402
from snapshot_positions import positions  # noqa: E402

RSUN, MSUN, G = 6.957e10, 1.98841e33, 6.67430e-8


def non_finite_stops_with_dump(exe, config, tmp):
    """A particle at the centre (no accretion radius) has an undefined gravitational acceleration: the
    run must stop naming particle, field and step, exit 3, and leave a readable debug dump."""
    n = 2000
    rng = np.random.default_rng(1)
    r = 1 + 0.05 * rng.standard_normal(n)
    phi = rng.uniform(0, 2 * np.pi, n)
    r[7] = 0.0
    v = np.where(r > 0, 1 / np.sqrt(np.maximum(r, 1e-3)), 0.0)
    ic = tmp / "centre.hdf5"
    with h5py.File(ic, "w") as f:
        f.create_group("Header").attrs["Time"] = 40.0
        g = f.create_group("PartType0")
        g["Coordinates"] = np.c_[r * np.cos(phi), r * np.sin(phi), np.zeros(n)]
        g["Velocities"] = np.c_[-v * np.sin(phi), v * np.cos(phi), np.zeros(n)]
        g["Masses"] = np.full(n, 1e-10 / n)
        g["ParticleIDs"] = np.arange(n, dtype=np.uint64)
    # The leapfrog meets it in the acceleration at step 0; block steps (gravity in substeps) in the
    # drifted position at the end of their first cycle.
    block = subprocess.run([exe, "run", str(config), "-q", "-o", str(tmp / "nan_block"), "--set",
                            f'problem.initial_conditions="{ic}"', "--set", "physics.accretion_radius=0.0",
                            "--set", 'integrator.scheme="block"'], capture_output=True, text=True)
    block_dump = tmp / "nan_block" / "debug_step_1.hdf5"
    block_named = all(w in block.stderr for w in ("non-finite position", "particle ID 7", str(block_dump)))
    out = tmp / "nan_run"
    p = subprocess.run([exe, "run", str(config), "-q", "-o", str(out), "--set", f'problem.initial_conditions="{ic}"',
                        "--set", "physics.accretion_radius=0.0", "--set", 'integrator.scheme="leapfrog"'],
                       capture_output=True, text=True)
    dump = out / "debug_step_0.hdf5"
    named = all(w in p.stderr for w in ("non-finite acceleration", "particle ID 7", "step 0", str(dump)))
    with h5py.File(dump) as d:
        acc = d["PartType0/Acceleration"][:] if "PartType0/Acceleration" in d else None
        ids = d["PartType0/ParticleIDs"][:]
    bad_in_dump = acc is not None and not np.isfinite(acc[ids == 7]).all() and np.isfinite(acc[ids != 7]).all()
    return [("non-finite value stops the run with exit 3", p.returncode == 3 and p.stderr.count("\n") == 1),
            ("error names field, particle and step", named),
            ("debug dump holds the bad particle", bad_in_dump),
            ("block steps: exit 3, one line naming position and particle, dump written",
             block.returncode == 3 and block.stderr.count("\n") == 1 and block_named and block_dump.exists())]


def output_times_and_disc_analysis(exe, config, ic, tmp):
    """A user's disc from a file: output times in code units or in orbits, no ring parameter needed,
    and `analyze` gives radial profiles instead of the ring's analytic comparison."""
    ic_set = ["--set", f'problem.initial_conditions="{ic}"', "--set", "physics.accretion_radius=0.0",
              "--set", "problem.tau_start=1e9"]  # a ring parameter that no longer matters
    checks = []
    by_time = subprocess.run([exe, "run", str(config), "-q", "-o", str(tmp / "times"), *ic_set,
                              "--set", "output.times=[40.5, 41.0]"], capture_output=True, text=True)
    checks.append(("output.times: a disc from a file runs without ring parameters", by_time.returncode == 0))
    if by_time.returncode == 0:
        with h5py.File(tmp / "times" / "snapshot_002.hdf5") as s2:
            checks.append(("output.times: snapshot at t = 41.0", abs(s2["Header"].attrs["Time"] - 41.0) < 1e-9))
            checks.append(("Header Problem names the file's set-up", s2["Header"].attrs["Problem"] == b"initial_conditions"
                           or s2["Header"].attrs["Problem"] == "initial_conditions"))
        checks.append(("the run ends with radial profiles, not the ring's accuracy table",
                       "Mdot_in" in by_time.stdout and "tau*/tau" not in by_time.stdout))
        js = tmp / "profiles.json"
        subprocess.run([exe, "analyze", str(tmp / "times" / "snapshot_002.hdf5"), "--json", str(js)],
                       check=True, stdout=subprocess.DEVNULL)
        prof = json.loads(js.read_text())
        counted = sum(b["count"] for b in prof["bins"])
        mass = sum(b["sigma"] * np.pi * (b["r_hi"] ** 2 - b["r_lo"] ** 2) for b in prof["bins"])
        checks.append(("analyze: profiles bin every particle and their mass", prof.get("problem") == "disc"
                       and counted == prof["particles"] and abs(mass / prof["mass"] - 1) < 1e-12))
        inner = max(prof["bins"], key=lambda b: b["count"])
        checks.append(("analyze: Kepler j = sqrt(G M r) at the densest bin (G M = 1)",
                       abs(inner["j"] / np.sqrt(0.5 * (inner["r_lo"] + inner["r_hi"])) - 1) < 0.02))
    period = 2 * np.pi * 1.0 ** 1.5
    by_orbit = subprocess.run([exe, "run", str(config), "-q", "-o", str(tmp / "orbits"), *ic_set,
                               "--set", "output.orbits=[6.5]"], capture_output=True, text=True)
    ok = by_orbit.returncode == 0
    if ok:
        with h5py.File(tmp / "orbits" / "snapshot_001.hdf5") as s1:
            ok = abs(s1["Header"].attrs["Time"] - 6.5 * period) < 1e-9
    checks.append(("output.orbits: snapshot at 6.5 orbits of r0 (t = 13 pi)", ok))
    both = subprocess.run([exe, "run", str(config), "-q", "-o", str(tmp / "both"), *ic_set,
                           "--set", "output.orbits=[6.5]", "--set", "output.times=[41]"], capture_output=True, text=True)
    checks.append(("output.times and output.orbits together: one-line error, exit 2, nothing written",
                   both.returncode == 2 and both.stderr.count("\n") == 1 and "not both" in both.stderr
                   and not (tmp / "both").exists()))
    return checks


def file_of_another_mass(exe, config, tmp):
    """A file as h5py writes it (Header Problem a Python str, a variable-length string), of another
    total mass than problem.disc_mass: `analyze` reads it and, without the ring's Header attributes,
    gives radial profiles; a run from it records the file's mass as its initial disc mass
    (Header DiskMass), so its mass budget is that of round-off."""
    n = 1500
    rng = np.random.default_rng(8)
    r = np.sqrt(rng.uniform(0.8**2, 1.2**2, n))
    phi = rng.uniform(0, 2 * np.pi, n)
    v = 1 / np.sqrt(r)
    masses = rng.uniform(0.5, 1.5, n) * 1e-6 / n
    checks = []
    for name, problem in (("plain.hdf5", None), ("h5py_str.hdf5", "initial_conditions")):
        with h5py.File(tmp / name, "w") as f:
            h = f.create_group("Header")
            h.attrs["Time"] = 0.0
            if problem:
                h.attrs["Problem"] = problem
            g = f.create_group("PartType0")
            g["Coordinates"] = np.c_[r * np.cos(phi), r * np.sin(phi), np.zeros(n)]
            g["Velocities"] = np.c_[-v * np.sin(phi), v * np.cos(phi), np.zeros(n)]
            g["Masses"] = masses
            g["ParticleIDs"] = np.arange(1, n + 1, dtype=np.uint64)
        a = subprocess.run([exe, "analyze", str(tmp / name)], capture_output=True, text=True)
        checks.append((f"analyze of a hand-made file ({'Problem a variable-length string' if problem else 'no Problem'}): "
                       "radial profiles", a.returncode == 0 and "Mdot_in" in a.stdout))
    out = tmp / "other_mass"
    run = subprocess.run([exe, "run", str(config), "-o", str(out), "--set", f'problem.initial_conditions="{tmp / "h5py_str.hdf5"}"',
                          "--set", "output.times=[0.5]", "--set", "output.progress_interval=0"], capture_output=True, text=True)
    ok = run.returncode == 0
    if ok:
        with h5py.File(out / "snapshot_001.hdf5") as s1:
            disc_mass = s1["Header"].attrs["DiskMass"]
        budget = [line for line in run.stdout.splitlines() if line.startswith("mass budget")]
        ok = abs(disc_mass / masses.sum() - 1) < 1e-14 and len(budget) == 1 and abs(float(budget[0].split()[-1])) < 1e-12
    checks.append(("a file of another mass than problem.disc_mass: DiskMass is the file's, the mass budget round-off", ok))
    return checks


def main():
    exe = sys.argv[1]
    checks = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        n = 3000
        rng = np.random.default_rng(5)
        r = 0.5 * (1.0 + 0.05 * rng.standard_normal(n))  # file length unit is 2 Rsun: ring at r0 = 1 Rsun
        phi = rng.uniform(0, 2 * np.pi, n)
        L = 2 * RSUN
        T = np.sqrt(L**3 / (G * MSUN))
        v = np.sqrt(1.0 / r)  # Kepler in file units (G M = 1 there too)
        ic = tmp / "ic.hdf5"
        with h5py.File(ic, "w") as f:
            f.create_group("Header").attrs["Time"] = 40.0 / 2**1.5  # 40 code time units of the run
            u = f.create_group("Units")
            u.attrs["UnitLength_in_cm"] = L
            u.attrs["UnitMass_in_g"] = MSUN
            u.attrs["UnitTime_in_s"] = T
            g = f.create_group("PartType0")
            g["Coordinates"] = np.c_[r * np.cos(phi), r * np.sin(phi), np.zeros(n)]
            g["Velocities"] = np.c_[-v * np.sin(phi), v * np.cos(phi), np.zeros(n)]
            g["Masses"] = np.full(n, 1e-10 / n)
            g["ParticleIDs"] = np.arange(10, 10 + n, dtype=np.uint64)[::-1].copy()
        out = tmp / "run"
        tau0 = 12 * 4.7786e-5 * 40.0
        config = Path(__file__).resolve().parents[2] / "configs" / "ring.toml"
        subprocess.run([exe, "run", str(config), "-q", "-o", str(out), "--set", f"problem.initial_conditions={str(ic)!r}".replace("'", '"'),
                        "--set", f"output.tau=[{tau0 + 0.0005}]", "--set", "physics.accretion_radius=0.0"],
                       check=True, stdout=subprocess.DEVNULL)
        with h5py.File(out / "snapshot_000.hdf5") as s0, h5py.File(out / "snapshot_001.hdf5") as s1:
            ids = s1["PartType0/ParticleIDs"][:]
            checks.append(("all IDs kept, in ID order", np.array_equal(ids, np.arange(10, 10 + n))))
            checks.append(("masses kept", np.allclose(s1["PartType0/Masses"][:], 1e-10 / n, rtol=1e-15)))
            r0 = np.hypot(*positions(s0, 2).T)
            # The file lists IDs in descending order, the snapshot in ascending order.
            checks.append(("positions converted to code units", np.allclose(r0, 2 * r[::-1], rtol=1e-12)))
            checks.append(("starts at the file's time", abs(s0["Header"].attrs["Time"] - 40.0) < 1e-9))
            checks.append(("smoothing length calibrated", s0["PartType0/SmoothingLength"][0] > 0))
        checks += output_times_and_disc_analysis(exe, config, ic, tmp)
        checks += non_finite_stops_with_dump(exe, config, tmp)
        checks += file_of_another_mass(exe, config, tmp)
    return summarise("initial conditions", checks)


if __name__ == "__main__":
    sys.exit(main())
