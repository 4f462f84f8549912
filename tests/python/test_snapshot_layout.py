#!/usr/bin/python3
"""Snapshots with and without Header/PointMassPosition are read alike (plain script, no pytest).

    /usr/bin/python3 tests/python/test_snapshot_layout.py SPHDISK SNAPSHOT.hdf5

Snapshots store Coordinates in [0, BoxSize]^3 with the central mass at PointMassPosition; files
without it (written before it existed, or made by hand) hold positions relative to the central mass.
Checks:
- tests/fixtures/snapshot_origin_centred.hdf5 (400 ring particles, written before PointMassPosition
  existed) gives the `sphdisk analyze` text and JSON recorded when it was written;
- SNAPSHOT and an origin-centred copy of it (Coordinates - PointMassPosition, the attribute removed)
  give the same `analyze` output, the same radii in tools/report.py, and the same first snapshot when
  a run starts from each (problem.initial_conditions): every reader subtracts what the writer added.
Prints each check; exits 1 if any failed.
"""
import json
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
FIXTURE = os.path.join(ROOT, "tests", "fixtures", "snapshot_origin_centred")
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.dont_write_bytecode = True  # no tools/__pycache__ in the work tree
from checklist import Checks  # noqa: E402
import report  # noqa: E402

check = Checks()


def analyze(exe, path, json_path):
    """`sphdisk analyze` text output and JSON of one snapshot."""
    res = subprocess.run([exe, "analyze", path, "--json", json_path], capture_output=True, text=True)
    if res.returncode != 0:
        return f"exit {res.returncode}: {res.stderr.strip()}", ""
    with open(json_path) as fh:
        return res.stdout, fh.read()


def origin_centred_copy(src, dst):
    """dst: src with Coordinates relative to the central mass and no PointMassPosition (the older layout)."""
    with h5py.File(src, "r") as f_in, h5py.File(dst, "w") as f_out:
        for name in f_in:
            f_in.copy(name, f_out)
        centre = f_out["Header"].attrs["PointMassPosition"]
        f_out["PartType0/Coordinates"][...] = f_out["PartType0/Coordinates"][:] - centre
        del f_out["Header"].attrs["PointMassPosition"]


def numbers(value):
    """Every number in a parsed JSON value, in order."""
    if isinstance(value, dict):
        return [x for v in value.values() for x in numbers(v)]
    if isinstance(value, list):
        return [x for v in value for x in numbers(v)]
    return [float(value)] if isinstance(value, (int, float)) else []


def check_fixture(exe, tmp):
    text, js = analyze(exe, FIXTURE + ".hdf5", os.path.join(tmp, "fixture.json"))
    with open(FIXTURE + ".analysis.txt") as fh:
        check(text == fh.read(), "origin-centred fixture: analyze prints what it did when the fixture was written")
    # The JSON's 10 digits are compared to 1e-9, so that another libm's last bit cannot fail the test;
    # positions read with a wrong offset would change them by far more.
    with open(FIXTURE + ".analysis.json") as fh:
        want = json.load(fh)
    got = json.loads(js) if js else {}
    same = got.keys() == want.keys() and np.allclose(numbers(got), numbers(want), rtol=1e-9, atol=0)
    check(same, "origin-centred fixture: analyze writes the JSON it did then (to 1e-9)")


def check_copy_analyses_alike(exe, snapshot, centred, tmp):
    new = analyze(exe, snapshot, os.path.join(tmp, "new.json"))
    old = analyze(exe, centred, os.path.join(tmp, "old.json"))
    check(new[0] == old[0] and new[0].startswith("# tau"), "analyze: same text for the snapshot and its centred copy")
    check(new[1] == old[1] and new[1] != "", "analyze: same JSON for the snapshot and its centred copy")
    a, b = report.read_particles(snapshot), report.read_particles(centred)
    check(np.array_equal(a["r"], b["r"]) and np.array_equal(a["xy"], b["xy"]),
          "report.py: same positions and radii for the snapshot and its centred copy")
    with h5py.File(snapshot) as f:
        x = f["PartType0/Coordinates"][:]
        box = f["Header"].attrs["BoxSize"]
    check(bool(np.all(x >= 0) and np.all(x <= box)), f"snapshot Coordinates lie in [0, BoxSize] (BoxSize {box.tolist()})")


def first_snapshot(exe, initial_conditions, out):
    """Datasets of snapshot_000 of a one-step run started from initial_conditions, by name."""
    config = os.path.join(ROOT, "tests", "validation", "small_ring.toml")
    res = subprocess.run([exe, "run", config, "-q", "-o", out, "--threads", "1",
                          "--set", f'problem.initial_conditions="{initial_conditions}"', "--set", "run.max_steps=1",
                          "--set", "output.tau=[1.0]"],
                         capture_output=True, text=True)
    if res.returncode != 0:
        print(f"sphdisk run from {initial_conditions}: exit {res.returncode}: {res.stderr.strip()}")
        return None
    with h5py.File(os.path.join(out, "snapshot_000.hdf5")) as f:
        return {k: f["PartType0"][k][:] for k in f["PartType0"]}


def check_runs_start_alike(exe, snapshot, centred, tmp):
    a = first_snapshot(exe, snapshot, os.path.join(tmp, "from_new"))
    b = first_snapshot(exe, centred, os.path.join(tmp, "from_old"))
    if not check(a is not None and b is not None, "runs start from the snapshot and from its centred copy"):
        return
    same = a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a)
    check(same, "runs started from either write the same snapshot_000 (every PartType0 dataset)")


def main(argv):
    if len(argv) != 2:
        print("usage: test_snapshot_layout.py SPHDISK SNAPSHOT.hdf5", file=sys.stderr)
        return 2
    exe, snapshot = argv
    with tempfile.TemporaryDirectory(prefix="sphdisk_layout_test_") as tmp:
        check_fixture(exe, tmp)
        centred = os.path.join(tmp, "centred.hdf5")
        origin_centred_copy(snapshot, centred)
        check_copy_analyses_alike(exe, snapshot, centred, tmp)
        check_runs_start_alike(exe, snapshot, centred, tmp)
    return check.exit_code("snapshot layout")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
