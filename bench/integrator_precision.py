#!/usr/bin/python3
"""Work against precision of the error-controlled integrators (docs/design.md, "Integrators"): runs
one ring configuration from tau 0.018 to TAU with each (scheme, tolerance) and measures the end
state's distance from a reference run (the first scheme at a tolerance 100x tighter than the
tightest asked): the rms and largest |x - x_ref| / |x_ref| and |v - v_ref| / |v_ref| over the
particles, matched by ID, beside the rate evaluations and particle updates per particle.

Usage: bench/integrator_precision.py [--config FILE] [--exe BINARY] [--tau TAU] [--set KEY=VALUE ...]
           [--schemes rk45[,...]] [--tolerances 1e-4,1e-5,...] N
Runs go to runs/integrator_precision/<scheme>_<tolerance>; the table is printed and written as CSV to
runs/integrator_precision/table.csv.
"""
import argparse
import csv
import json
import pathlib
import subprocess
import sys

import h5py
import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent


def run(exe, config, n, tau, scheme, tol, sets, out):
    cmd = [str(exe), "run", str(config), "-q", "--overwrite", "-o", str(out), "-t", "1",
           "--set", f"problem.particles={n}", "--set", f"output.tau=[{tau}]",
           "--set", f'integrator.scheme="{scheme}"', "--set", f"integrator.tolerance={tol}",
           "--set", "checkpoint.every_seconds=0"]
    for s in sets:
        cmd += ["--set", s]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"integrator_precision: {scheme} at tolerance {tol} failed:\n{done.stderr[-2000:]}")
    steps = json.loads((out / "ranks.json").read_text())[0]["steps"]
    with h5py.File(out / "snapshot_001.hdf5", "r") as f:
        part = f["PartType0"]
        order = np.argsort(part["ParticleIDs"][:])
        return steps, part["Coordinates"][:][order], part["Velocities"][:][order]


def relative(a, ref):
    e = np.linalg.norm(a - ref, axis=1) / np.linalg.norm(ref, axis=1)
    return float(np.sqrt(np.mean(e**2))), float(e.max())


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--config", default=str(ROOT / "configs/ring_cold.toml"))
    ap.add_argument("--exe", default=str(ROOT / "build/release/sphdisk"))
    ap.add_argument("--tau", type=float, default=0.027)
    ap.add_argument("--set", action="append", default=[], dest="sets")
    ap.add_argument("--schemes", default="rk45")
    ap.add_argument("--tolerances", default="1e-4,1e-5,1e-6,1e-7,1e-8")
    ap.add_argument("n", type=int)
    a = ap.parse_args()
    schemes = a.schemes.split(",")
    tols = [float(t) for t in a.tolerances.split(",")]
    base = ROOT / "runs/integrator_precision"
    ref_tol = min(tols) / 100
    _, x_ref, v_ref = run(a.exe, a.config, a.n, a.tau, schemes[0], ref_tol, a.sets, base / f"reference_{schemes[0]}_{ref_tol:g}")
    rows = []
    for scheme in schemes:
        for tol in tols:
            steps, x, v = run(a.exe, a.config, a.n, a.tau, scheme, tol, a.sets, base / f"{scheme}_{tol:g}")
            xr, xm = relative(x, x_ref)
            vr, vm = relative(v, v_ref)
            rows.append({"scheme": scheme, "tolerance": tol, "steps": steps["steps"],
                         "rate_evaluations": steps["rate_evaluations"],
                         "updates_per_particle": round(steps["particle_updates"] / a.n),
                         "x_rms": f"{xr:.3e}", "x_max": f"{xm:.3e}", "v_rms": f"{vr:.3e}", "v_max": f"{vm:.3e}"})
            print(" ".join(f"{k}={val}" for k, val in rows[-1].items()), flush=True)
    with open(base / "table.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"reference: {schemes[0]} at tolerance {ref_tol:g}; N = {a.n}, tau 0.018 -> {a.tau}; {base / 'table.csv'}")


if __name__ == "__main__":
    main()
