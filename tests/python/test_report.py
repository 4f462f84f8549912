#!/usr/bin/python3
"""Test of tools/report.py on synthetic runs from tools/make_test_run.py (plain script, no pytest).

    /usr/bin/python3 tests/python/test_report.py

Prints each check; exits 1 if any failed.
"""
import json
import math
import os
import re
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import numpy as np  # noqa: E402
from scipy.integrate import quad  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
TOOLS = os.path.join(ROOT, "tools")
REPORT = os.path.join(TOOLS, "report.py")
MAKE_RUN = os.path.join(TOOLS, "make_test_run.py")
sys.path.insert(0, TOOLS)
sys.dont_write_bytecode = True  # no tools/__pycache__ in the work tree
import report  # noqa: E402
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checklist import Checks  # noqa: E402

W, H = 640, 480
SNAPSHOT_FIGURES = {"fig5_positions.png": (640, 640), "fig6_sigma.png": (W, H), "fig7_vr.png": (W, H),
                    "fig8_binned_sigma.png": (W, H), "error_vs_time.png": (W, H)}
DIAG_FIGURES = {"conservation.png": (W, H)}
SCALING_FIGURES = {"fig9_speedup.png": (W, H), "fig9_efficiency.png": (W, H), "fig10_comm_time.png": (W, H)}

check = Checks()


def run(*args):
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, timeout=300)


def make_run(path, *extra):
    res = run(MAKE_RUN, path, "--particles", "3000", *extra)
    if not check(res.returncode == 0, f"make_test_run.py {' '.join(extra)} -> {path}"):
        print(res.stderr)
    return res.returncode == 0


def check_png(path, size):
    name = os.path.basename(path)
    if not check(os.path.isfile(path), f"{name} exists"):
        return
    img = mpimg.imread(path)
    check(img.ndim == 3 and (img.shape[1], img.shape[0]) == size,
          f"{name} is {size[0]}x{size[1]} px (got {img.shape[1]}x{img.shape[0]})")
    check(float(np.std(img[..., :3])) > 0, f"{name} is not blank")


def check_report_md(out_dir, figures):
    md_path = os.path.join(out_dir, "report.md")
    if not check(os.path.isfile(md_path), "report.md exists"):
        return ""
    md = open(md_path, encoding="utf-8").read()
    for name in figures:
        check(f"]({name})" in md, f"report.md links {name}")
    check(md.startswith("# "), "report.md has a title")
    check("| problem.particles | 3000 |" in md, "report.md has the /Parameters table")
    return md


def accuracy_rows(md):
    """(tau, L1, scatter) rows of the report's accuracy table (the annulus-mass L1 is checked apart)."""
    rows = []
    for line in md.splitlines():
        m = re.match(r"\| snapshot_\d+\.hdf5 \| [^|]+ \| ([^|]+) \| \d+ \| ([^|]+) \| ([^|]+) \| ([^|]+) \|", line)
        if m:
            tau, l1, l1_mass, scatter = (float(v) for v in m.groups())
            rows.append((tau, l1, scatter))
            check(l1_mass < 0.1, f"annulus mass/area L1 {l1_mass:.3f} < 0.1 for particles drawn from the analytic profile")
    return rows


def test_analytic():
    """report.Ring against the numbers in docs/physics.md sec. 4."""
    ring = report.Ring(tau=0.09, mass=1.0, r0=1.0, nu=1.0)
    for x, want in ((0.2, -49.0), (0.8, -12.4), (1.0, 0.76), (1.5, 34.0)):
        got = float(ring.vr_over_nu(x))
        check(abs(got - want) <= 0.02 * abs(want) + 0.01, f"analytic v_r/nu(x={x}, tau=0.09) = {got:.3f} ~ {want}")
    for tau in (0.018, 0.09):
        ring = report.Ring(tau=tau, mass=1.0, r0=1.0, nu=None)
        mass = quad(lambda r: 2 * math.pi * r * ring.sigma(r), 1e-9, 4.0, limit=200, points=[1.0])[0]
        check(abs(mass - 1.0) < 1e-6, f"analytic Sigma at tau={tau} integrates to the disc mass ({mass:.9f})")


def test_full_run(tmp):
    run_dir, out_dir = os.path.join(tmp, "full"), os.path.join(tmp, "full_out")
    if not make_run(run_dir, "--scaling"):
        return
    with open(os.path.join(run_dir, "timers.json"), "w") as fh:
        json.dump({"neighbours": 1.5, "density": 0.5}, fh)
    res = run(REPORT, run_dir, "--out", out_dir)
    if not check(res.returncode == 0, "report.py on a full synthetic run exits 0"):
        print(res.stderr)
        return
    figures = {**SNAPSHOT_FIGURES, **DIAG_FIGURES, **SCALING_FIGURES}
    for name, size in figures.items():
        check_png(os.path.join(out_dir, name), size)
    md = check_report_md(out_dir, figures)
    check("Wall time: 10.5 s" in md, "report.md gives the wall time of the last diagnostics row")
    check("| neighbours | 1.5 |" in md, "report.md lists timers.json")
    rows = accuracy_rows(md)
    check(len(rows) == 5, f"accuracy table has one row per snapshot ({len(rows)})")
    check(all(l1 < 0.02 for _, l1, _ in rows),
          "binned L1 error of synthetic data < 0.02 (independent analytic codes agree)")
    check(all(0.04 < s < 0.06 for _, _, s in rows), "per-particle scatter ~ the 5% noise put in")


def test_no_diagnostics(tmp):
    run_dir = os.path.join(tmp, "nodiag")
    if not make_run(run_dir, "--no-diagnostics", "--taus", "0.018,0.054"):
        return
    res = run(REPORT, run_dir)
    out_dir = os.path.join(run_dir, "report")
    if not check(res.returncode == 0, "report.py without diagnostics.csv exits 0 (default --out DIR/report)"):
        print(res.stderr)
        return
    for name, size in SNAPSHOT_FIGURES.items():
        check_png(os.path.join(out_dir, name), size)
    for name in (*DIAG_FIGURES, *SCALING_FIGURES):
        check(not os.path.exists(os.path.join(out_dir, name)), f"no {name} without its CSV")
    md = check_report_md(out_dir, SNAPSHOT_FIGURES)
    check("diagnostics.csv missing" in md, "report.md notes the missing diagnostics.csv")


def check_usage_error(args, what):
    res = run(REPORT, *args)
    lines = res.stderr.strip().splitlines()
    check(res.returncode == 2, f"{what}: exit code 2 (got {res.returncode})")
    check(len(lines) == 1 and lines[0].startswith("report.py: error:"),
          f"{what}: one-line message on stderr ({res.stderr.strip()!r})")


def test_errors(tmp):
    check_usage_error([os.path.join(tmp, "does_not_exist")], "missing run directory")
    empty = os.path.join(tmp, "empty")
    os.makedirs(empty)
    check_usage_error([empty], "run directory without snapshots")


def main():
    test_analytic()
    with tempfile.TemporaryDirectory(prefix="sphdisk_report_test_") as tmp:
        test_full_run(tmp)
        test_no_diagnostics(tmp)
        test_errors(tmp)
    return check.exit_code("report")


if __name__ == "__main__":
    sys.exit(main())
