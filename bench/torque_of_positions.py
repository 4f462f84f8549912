#!/usr/bin/python3
"""The SPH viscous torque that particle positions alone give, against the continuum's
(docs/validation.md, "What the viscous torque loses on disordered particles").

Usage:
  bench/torque_of_positions.py [--exe BIN] [--config FILE] [--neighbours K1,K2,...] [--set KEY=VALUE ...] SNAPSHOT.hdf5 [...]
      the snapshot's positions with Kepler velocities (bench/kepler_velocities.py), its viscosity
  bench/torque_of_positions.py [--exe BIN] [--config FILE] [--neighbours K1,K2,...] [--set KEY=VALUE ...] --random N[:SEED] [...]
      N particles placed at random from the analytic ring at tau = 0.126 (the set-up's placement)
  Each K is a neighbour number or auto (the default rule, docs/validation.md).

For each position set and neighbour number, one rate evaluation (`sphdisk run` with run.max_steps
= 1 from the positions) gives the accelerations, and bench/torque_efficiency.py projects their
torque on annuli 0.5-1.5 r0 onto the continuum's for the analytic Sigma that best fits the
positions: 1 when the discrete operator gives the continuum's torque for these positions.
"""
import argparse
import pathlib
import subprocess
import sys
import tempfile

import h5py

RSUN_CM = 6.957e10  # the configuration's length unit (solar radii) in cm: physics.viscosity is in Rsun^2 / s
ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
from torque_efficiency import efficiency  # noqa: E402


def evaluate(exe, config, sets, work):
    out = work / "run"
    cmd = [str(exe), "run", str(config), "-q", "--overwrite", "-o", str(out), "-t", "1", "--set", "run.max_steps=1",
           "--set", "output.tau=[0.5]", "--set", "checkpoint.every_seconds=0"] + [a for s in sets for a in ("--set", s)]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return efficiency(str(out / "snapshot_000.hdf5"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--exe", default=str(ROOT / "build/release/sphdisk"))
    ap.add_argument("--config", default=str(ROOT / "configs/ring_cold.toml"))
    ap.add_argument("--neighbours", default="60", help="comma-separated neighbour numbers (or auto)")
    ap.add_argument("--random", action="store_true", help="the arguments are N[:SEED] of random position sets")
    ap.add_argument("--set", action="append", default=[], help="a further setting of every evaluation")
    ap.add_argument("sets", nargs="+")
    a = ap.parse_args()
    print("positions | neighbours | tau* | SPH torque / continuum torque")
    with tempfile.TemporaryDirectory() as tmp:
        work = pathlib.Path(tmp)
        for item in a.sets:
            for k in a.neighbours.split(","):
                sets = [f"sph.neighbours={k}"] + a.set
                if a.random:
                    n, _, seed = item.partition(":")
                    sets += [f"problem.particles={n}", "problem.tau_start=0.126", f"problem.seed={seed or 42}"]
                else:
                    ic = work / "kepler.hdf5"
                    subprocess.run(["/usr/bin/python3", str(ROOT / "bench/kepler_velocities.py"), item, str(ic)], check=True)
                    with h5py.File(item) as f:
                        nu = f["Header"].attrs["KinematicViscosity"]
                        code_nu = f["Units"].attrs["Unit length in cgs (U_L)"] ** 2 / f["Units"].attrs["Unit time in cgs (U_t)"]
                    sets += [f'problem.initial_conditions="{ic}"', f"physics.viscosity={nu * code_nu / RSUN_CM**2:.6e}"]
                tau_fit, eff = evaluate(a.exe, a.config, sets, work)
                print(f"{item} | {k} | {tau_fit:.4f} | {eff:.3f}", flush=True)


if __name__ == "__main__":
    main()
