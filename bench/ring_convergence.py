#!/usr/bin/python3
"""The ring's convergence with N (docs/validation.md, "Convergence with N"): runs a ring
configuration (configs/ring.toml unless --config names another, e.g. configs/ring_cold.toml) at each N to tau = 0.09 and 0.126 and tabulates, per output, the best-fit viscous time tau*/tau, the
annulus-mass L1 against its sampling floor, the mean bias of the particles' SPH Sigma in the ring's
core (0.9 <= r <= 1.1, the paper's Fig. 8 measure) with and without its self term m W(0, h), steps,
wall time and peak memory.

Usage: bench/ring_convergence.py [--label L] [--config FILE] [--exe BINARY] [--threads T] [--set KEY=VALUE ...] [--report] N [N ...]
  --exe: the sphdisk binary (default build/release/sphdisk; a copy keeps a batch on one build).
  --set: passed to `sphdisk run` (e.g. --set 'integrator.scheme="block"'); --report also draws the
  run's figures (P98 Figs. 5-8). Runs go to runs/convergence/L_N<N>; the table is printed and
  appended as CSV rows to runs/convergence/L.csv (one row per N and output time).
"""
import argparse
import csv
import json
import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
EXE = ROOT / "build/release/sphdisk"
FIELDS = ["label", "N", "tau", "tau_fit_ratio", "l1_at_fit", "mass_sigma_l1", "sampling_floor", "l1_over_floor",
          "core_sph_sigma_bias", "core_sigma_noself_bias", "vr_drift_l1", "steps", "wall_s", "peak_rss_mib", "config", "settings"]


def run_one(exe, n, label, config, threads, sets, report):
    run_dir = ROOT / "runs/convergence" / f"{label}_N{n}"
    cmd = [str(exe), "run", str(config), "-q", "--overwrite", "-o", str(run_dir), "-t", str(threads),
           "--set", f"problem.particles={n}", "--set", "output.tau=[0.09, 0.126]"]
    for s in sets:
        cmd += ["--set", s]
    timed = subprocess.run(["/usr/bin/time", "-v"] + cmd, capture_output=True, text=True)
    if timed.returncode != 0:
        sys.exit(f"ring_convergence: the run of N = {n} failed:\n{timed.stderr[-2000:]}")
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([\d:.]+)", timed.stderr).group(1)
    wall_s = sum(float(x) * 60**k for k, x in enumerate(reversed(wall.split(":"))))
    rss_mib = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", timed.stderr).group(1)) / 1024
    steps = sum(1 for _ in open(run_dir / "diagnostics.csv")) - 2
    if report:
        subprocess.run([str(exe), "report", str(run_dir)], check=True, capture_output=True)
    rows = []
    for snap in ("snapshot_001.hdf5", "snapshot_002.hdf5"):
        out = run_dir / (snap.replace(".hdf5", "") + "_analysis.json")
        subprocess.run([str(exe), "analyze", str(run_dir / snap), "--json", str(out)], check=True, capture_output=True)
        a = json.loads(out.read_text())
        rows.append({"label": label, "N": n, "tau": round(a["tau"], 4), "tau_fit_ratio": round(a["tau_fit"] / a["tau"], 4),
                     "l1_at_fit": round(a["mass_sigma_l1_at_fit"], 4), "mass_sigma_l1": round(a["mass_sigma_l1"], 4),
                     "sampling_floor": round(a["sampling_floor"], 4),
                     "l1_over_floor": round(a["mass_sigma_l1"] / a["sampling_floor"], 2),
                     "core_sph_sigma_bias": round(a["core_sigma_bias"], 4),
                     "core_sigma_noself_bias": round(a["core_sigma_noself_bias"], 4), "vr_drift_l1": round(a["vr_drift_l1"], 4),
                     "steps": steps, "wall_s": round(wall_s, 1), "peak_rss_mib": round(rss_mib), "config": config.name,
                     "settings": " ".join(sets)})
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--label", default="default")
    ap.add_argument("--config", type=pathlib.Path, default=ROOT / "configs/ring.toml")
    ap.add_argument("--exe", type=pathlib.Path, default=EXE)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--set", action="append", default=[], dest="sets")
    ap.add_argument("--report", action="store_true")
    ap.add_argument("sizes", nargs="+", type=int)
    args = ap.parse_args()
    table = ROOT / "runs/convergence" / f"{args.label}.csv"
    table.parent.mkdir(parents=True, exist_ok=True)
    new = not table.exists()
    with open(table, "a", newline="") as f:
        w = csv.DictWriter(f, FIELDS)
        if new:
            w.writeheader()
        for n in args.sizes:
            for row in run_one(args.exe.resolve(), n, args.label, args.config.resolve(), args.threads, args.sets, args.report):
                w.writerow(row)
                f.flush()
                print(" | ".join(str(row[k]) for k in FIELDS), flush=True)


if __name__ == "__main__":
    main()
