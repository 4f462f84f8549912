#!/usr/bin/python3
"""Test of tools/report.py on synthetic runs from tools/make_test_run.py (plain script, no pytest).

    /usr/bin/python3 tests/python/test_report.py

Prints each check; exits 1 if any failed.
"""
import csv
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import time

import h5py
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
import make_test_run  # noqa: E402
import report  # noqa: E402
import report_images  # noqa: E402
import report_text  # noqa: E402
import ring_model  # noqa: E402
import run_data  # noqa: E402
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checklist import Checks  # noqa: E402

# Pixel sizes at 300 dpi: one column 3.5 in (1050 px), two columns 7 in (2100 px).
COLUMN, SQUARE, MAP, WIDE, GRID = (1050, 780), (1050, 1050), (1050, 840), (2100, 840), (2100, 1500)
SNAPSHOT_FIGURES = {"fig5_positions.png": SQUARE, "fig6_sigma.png": COLUMN, "fig7_vr.png": WIDE,
                    "fig8_binned_sigma.png": COLUMN, "accreted_mass.png": COLUMN}
RING_FIGURES = {**SNAPSHOT_FIGURES, "error_vs_time.png": COLUMN}
DISC_FIGURES = {**SNAPSHOT_FIGURES, "disc_profiles.png": GRID}
DIAG_FIGURES = {"conservation.png": GRID}
SCALING_FIGURES = {"fig9_speedup.png": COLUMN, "fig9_efficiency.png": COLUMN, "fig10_comm_time.png": COLUMN}
TAB_RED = np.array([0.839, 0.153, 0.157])  # colour of the analytic curves

check = Checks()


def run(*args):
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, timeout=300)


def make_run(path, *extra):
    res = run(MAKE_RUN, path, "--particles", "3000", *extra)
    if not check(res.returncode == 0, f"make_test_run.py {' '.join(extra)} -> {path}"):
        print(res.stderr)
    return res.returncode == 0


def maps_of(n):
    return {f"sigma_map_{i:03d}.png": MAP for i in range(n)}


def check_figure(path, size):
    """The PNG at its pixel size and not blank, and its PDF beside it."""
    name = os.path.basename(path)
    if not check(os.path.isfile(path), f"{name} exists"):
        return
    img = mpimg.imread(path)
    check(img.ndim == 3 and (img.shape[1], img.shape[0]) == size,
          f"{name} is {size[0]}x{size[1]} px (got {img.shape[1]}x{img.shape[0]})")
    check(float(np.std(img[..., :3])) > 0, f"{name} is not blank")
    pdf = os.path.splitext(path)[0] + ".pdf"
    ok = os.path.isfile(pdf) and os.path.getsize(pdf) > 1000
    with open(pdf if ok else os.devnull, "rb") as fh:
        check(ok and fh.read(5) == b"%PDF-", f"{os.path.basename(pdf)} is a PDF")


def red_pixels(path):
    """Pixels in the colour of the analytic curves."""
    img = mpimg.imread(path)[..., :3]
    return int(np.sum(np.all(np.abs(img - TAB_RED) < 0.04, axis=-1)))


def bad_numbers(md):
    """NaN/inf words and numbers of magnitude 1e20 or more (or 1e-20 or less) in the text."""
    words = re.findall(r"\b(?:nan|inf|infinity)\b", md, re.IGNORECASE)
    huge = [m for m in re.findall(r"\d[eE]([+-]?\d+)", md) if abs(int(m)) >= 20]
    return words + huge


def check_report_md(out_dir, figures, particles=3000):
    md_path = os.path.join(out_dir, "report.md")
    if not check(os.path.isfile(md_path), "report.md exists"):
        return ""
    md = open(md_path, encoding="utf-8").read()
    for name in figures:
        check(f"]({name})" in md, f"report.md links {name}")
    check(md.startswith("# "), "report.md has a title")
    check(f"| problem.particles | {particles} |" in md, "report.md has the /Parameters table")
    order = [md.find(h) for h in ("## Summary", "## Figures", "## Details")]
    check(all(i >= 0 for i in order) and order == sorted(order), "report.md: summary, then figures, then details")
    check(not bad_numbers(md), f"report.md holds no NaN, inf or absurd number ({bad_numbers(md)[:5]})")
    return md


def summary_of(md):
    return md[md.find("## Summary"):md.find("## Figures")]


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


def read_profiles(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


# ----------------------------------------------------------------------------- analytic and measures

def test_analytic():
    """ring_model.Ring against the numbers in docs/physics.md sec. 4."""
    ring = report.Ring(tau=0.09, mass=1.0, r0=1.0, nu=1.0)
    for x, want in ((0.2, -49.0), (0.8, -12.4), (1.0, 0.76), (1.5, 34.0)):
        got = float(ring.vr_over_nu(x))
        check(abs(got - want) <= 0.02 * abs(want) + 0.01, f"analytic v_r/nu(x={x}, tau=0.09) = {got:.3f} ~ {want}")
    for tau in (0.018, 0.09):
        ring = report.Ring(tau=tau, mass=1.0, r0=1.0, nu=None)
        mass = quad(lambda r: 2 * math.pi * r * ring.sigma(r), 1e-9, 4.0, limit=200, points=[1.0])[0]
        check(abs(mass - 1.0) < 1e-6, f"analytic Sigma at tau={tau} integrates to the disc mass ({mass:.9f})")


def test_ring_measures():
    """tau* recovers the viscous time of an exact profile; the sampling floor is the mean L1 of random draws."""
    ring = ring_model.Ring(tau=0.09, mass=1.0, r0=1.0, nu=None)
    edges = np.linspace(0.05, 2.05, 51)
    tau_fit, l1 = ring_model.fit_tau(ring, edges, ring_model.annulus_mean_analytic(ring, edges, tau=0.081))
    check(abs(tau_fit - 0.081) <= 0.0005 * 0.09 and l1 < 1e-9, f"tau* of the exact profile at 0.081: {tau_fit:.5f}")
    rng = np.random.default_rng(7)
    n, area = 3000, np.pi * (edges[1:] ** 2 - edges[:-1] ** 2)
    ana = ring_model.annulus_mean_analytic(ring, edges)
    l1s = []
    for _ in range(200):
        r = make_test_run.sample_radii(rng, n, 0.09)
        m, _ = np.histogram(r, bins=edges)
        l1s.append(ring_model.l1_against(m * (1.0 / n) / area, ana))
    floor = ring_model.sampling_floor(ring, edges, n)
    check(abs(np.mean(l1s) / floor - 1.0) < 0.1,
          f"sampling floor {floor:.4f} ~ mean L1 of 200 random draws {np.mean(l1s):.4f}")


def test_ring_rule():
    """Ring runs: Header Problem "ring"; without Problem, where the ring's Header attributes are there,
    unless started from a file."""
    ring = {"ViscousTime": 0.05, "KinematicViscosity": 4.8e-5, "DiskMass": 1e-10}
    cases = [({"Problem": "ring"}, {}, True), ({"Problem": b"ring"}, {}, True), ({"Problem": "disc"}, {}, False),
             (ring, {}, True), ({}, {}, False), ({**ring, "ViscousTime": 0.0}, {}, False),
             (ring, {"problem.initial_conditions": ""}, True), (ring, {"problem.initial_conditions": "ic.hdf5"}, False),
             ({"Problem": "ring"}, {"problem.initial_conditions": "ic.hdf5"}, True)]
    for header, params, want in cases:
        check(ring_model.is_ring_run(header, params) == want, f"is_ring_run({header}, {params}) = {want}")
    # The ranks and threads of a run and its resumes, from run.log's line per process.
    with tempfile.TemporaryDirectory() as d:
        with open(os.path.join(d, "run.log"), "w") as f:
            f.write("==== sphdisk run ====\nranks: 3, threads: 1 per rank, vector loops: avx512\n"
                    "==== sphdisk resume ====\nranks: 1, threads: 2 per rank, vector loops: avx512\n")
        seen = report_text.workers_text(type("Run", (), {"run_dir": d, "params": {}, "ranks": [{}]})())
        check(seen == "3 MPI ranks x 1 thread, then 1 MPI rank x 2 threads (run.log: the run and its resumes)",
              f"workers of a run resumed on other counts: {seen!r}")
    # The wall time of a run and its resumes: diagnostics.csv's column restarts at each resume.
    check(report_text.run_wall_time([0.5, 1.0, 2.0]) == (2.0, 1), "wall time of one process: its last value")
    check(abs(report_text.run_wall_time([0.5, 2.0, 0.3, 1.5, 0.2, 0.7])[0] - 4.2) < 1e-12 and report_text.run_wall_time([0.5, 2.0, 0.3, 1.5, 0.2, 0.7])[1] == 3, "wall time over two resumes: the parts' sum")


# ----------------------------------------------------------------------------- column-density maps

def test_render():
    """Kernel sum on a lattice, a single particle's peak, mass conservation, orientation and speed."""
    s = 0.01
    g = np.arange(-1.0, 1.0, s) + s / 2
    xy = np.column_stack([a.ravel() for a in np.meshgrid(g, g)])
    m = np.full(len(xy), 2e-4)
    image = report_images.render_column_density(xy, m, np.full(len(xy), 1.5 * s), 0.5, 128)
    inner = image[16:-16, 16:-16] / (2e-4 / s**2)
    worst = float(np.max(np.abs(inner - 1.0)))
    check(worst < 0.01, f"lattice: Sigma = m / spacing^2 within 1% (worst {worst:.4f})")

    one = report_images.render_column_density(np.array([[0.005, 0.005]]), np.array([1.0]), np.array([0.1]), 0.5, 100)
    peak = 10.0 / (7.0 * math.pi * 0.1**2)
    check(abs(one[50, 50] / peak - 1.0) < 0.01, f"single particle: peak = m sigma_2 / h^2 ({one[50, 50] / peak:.4f})")

    rng = np.random.default_rng(3)
    xy = rng.uniform(-0.6, 0.6, (5000, 2))
    h = rng.uniform(0.0005, 0.2, 5000)
    img = report_images.render_column_density(xy, np.ones(5000), h, 0.5, 64)
    dx = 1.0 / 64
    inside = np.all(np.abs(xy) < 0.5 - 2 * h[:, None], axis=1)
    upper = np.all(np.abs(xy) < 0.5 + 2 * h[:, None], axis=1)
    total = img.sum() * dx**2
    check(inside.sum() - 1e-9 <= total <= upper.sum() + 1e-9,
          f"mass in the frame {total:.3f} between the particles wholly inside ({inside.sum()}) "
          f"and those touching it ({upper.sum()})")
    tiny = report_images.render_column_density(xy[:100] * 0.5, np.ones(100), np.full(100, 1e-5), 0.5, 64)
    check(abs(tiny.sum() * dx**2 - 100.0) < 1e-9, "particles with h far below a pixel keep their mass")

    right = report_images.render_column_density(np.array([[0.3, 0.0]]), np.ones(1), np.full(1, 0.05), 0.5, 64)
    up = report_images.render_column_density(np.array([[0.0, 0.3]]), np.ones(1), np.full(1, 0.05), 0.5, 64)
    ry, rx = np.unravel_index(np.argmax(right), right.shape)
    uy, ux = np.unravel_index(np.argmax(up), up.shape)
    check(rx > 40 and 28 <= ry <= 35 and uy > 40 and 28 <= ux <= 35, "maps: columns are x, rows are y (origin lower)")

    n = 1_000_000
    r = 1.0 + 0.15 * rng.standard_normal(n)
    phi = rng.uniform(0, 2 * math.pi, n)
    xy = np.column_stack((r * np.cos(phi), r * np.sin(phi)))
    h = 0.0045 * np.exp(((r - 1.0) / 0.15) ** 2 / 4)
    start = time.perf_counter()
    report_images.render_column_density(xy, np.full(n, 1e-16), h, 2.0, 512)
    took = time.perf_counter() - start
    check(took < 60, f"1M particles on 512^2 pixels in {took:.1f} s (< 60 s on a busy machine; seconds when idle)")


# ----------------------------------------------------------------------------- runs

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
    figures = {**RING_FIGURES, **DIAG_FIGURES, **SCALING_FIGURES, **maps_of(5)}
    for name, size in figures.items():
        check_figure(os.path.join(out_dir, name), size)
    check(not os.path.exists(os.path.join(out_dir, "disc_profiles.png")), "ring run: no disc profile figure")
    md = check_report_md(out_dir, figures)
    check("Wall time: 10.5 s" in md, "report.md gives the wall time of the last diagnostics row")
    check("| neighbours | 1.5 |" in md, "report.md lists timers.json")
    rows = accuracy_rows(md)
    check(len(rows) == 5, f"accuracy table has one row per snapshot ({len(rows)})")
    check(all(l1 < 0.02 for _, l1, _ in rows),
          "binned L1 error of synthetic data < 0.02 (independent analytic codes agree)")
    check(all(0.04 < s < 0.06 for _, _, s in rows), "per-particle scatter ~ the 5% noise put in")
    check_ring_summary(summary_of(md))
    check(red_pixels(os.path.join(out_dir, "fig6_sigma.png")) > 100, "ring run: Fig. 6 draws the analytic curve")
    profiles = read_profiles(os.path.join(out_dir, "profiles.csv"))
    check(len(profiles) == 5 * 50, f"profiles.csv: 50 bins for each of 5 snapshots ({len(profiles)} rows)")
    check_ring_drift(run_dir, profiles)


def check_ring_summary(summary):
    check("N = 3000" in summary and "integrator `leapfrog`" in summary and "kernel `wendland_c4`" in summary,
          "summary: N, integrator and kernel")
    check("Time span: t = " in summary and "τ = 0.018 to 0.09" in summary, "summary: time span in t and τ")
    m = re.search(r"τ\*/τ = ([0-9.]+)", summary)
    check(m is not None and abs(float(m.group(1)) - 1.0) < 0.1,
          f"summary: τ*/τ ~ 1 for particles drawn at τ ({m and m.group(1)})")
    m = re.search(r"Annulus-mass L1 ([0-9.]+) = ([0-9.]+) × its sampling floor ([0-9.]+)", summary)
    check(m is not None and 0.5 < float(m.group(2)) < 1.6,
          f"summary: annulus-mass L1 ~ its sampling floor ({m and m.group(0)})")
    m = re.search(r"mass \+ accreted mass ([^,]+), L_z \+ accreted L_z ([^;]+);", summary)
    check(m is not None and float(m.group(1)) < 1e-12 and abs(float(m.group(2)) - 1e-4) < 2e-5,
          f"summary: conservation of mass and L_z from diagnostics.csv ({m and m.group(0)})")


def check_ring_drift(run_dir, profiles):
    """make_test_run's accelerations give the analytic v_r as guiding-centre drift, particle by particle."""
    path = os.path.join(run_dir, "snapshot_004.hdf5")
    parts = run_data.read_particles(path)
    want = make_test_run.vr_ring(parts["r"], 0.09)
    check(np.max(np.abs(parts["drift"] - want)) < 1e-9 * np.max(np.abs(want)), "guiding-centre drift = analytic v_r")
    last = [row for row in profiles if row["snapshot"] == "snapshot_004.hdf5" and row["count"] != "0"]
    drift = np.array([float(row["vr_drift"]) for row in last])
    vr = np.array([float(row["vr"]) for row in last])
    check(len(last) > 10 and np.allclose(drift, vr, rtol=1e-6, atol=0),
          "profiles.csv: binned drift = binned v_r (both analytic in the synthetic ring)")


def test_disc_run(tmp):
    """A power-law disc: profiles, no analytic curve or ring table, Mdot = 2 M V / 3 at every radius."""
    run_dir = os.path.join(tmp, "disc")
    if not make_run(run_dir, "--disc", "--inflow", "1e-3"):
        return
    res = run(REPORT, run_dir)
    out_dir = os.path.join(run_dir, "report")
    if not check(res.returncode == 0, "report.py on a power-law disc exits 0"):
        print(res.stderr)
        return
    figures = {**DISC_FIGURES, **DIAG_FIGURES, **maps_of(3)}
    for name, size in figures.items():
        check_figure(os.path.join(out_dir, name), size)
    check(not os.path.exists(os.path.join(out_dir, "error_vs_time.png")), "disc: no error-vs-time figure")
    md = check_report_md(out_dir, figures)
    for word in ("analytic", "P98", "τ*/τ", "Accuracy against", "sampling floor"):
        check(word not in md, f"disc report.md does not mention '{word}'")
    check("Not a ring run" in summary_of(md) and "`disc` (Header Problem)" in summary_of(md), "disc: summary says so")
    check("### Disc by snapshot" in md, "disc: per-snapshot table")
    for name in ("fig6_sigma.png", "fig7_vr.png", "fig8_binned_sigma.png"):
        check(red_pixels(os.path.join(out_dir, name)) == 0, f"disc: no analytic curve in {name}")
    profiles = read_profiles(os.path.join(out_dir, "profiles.csv"))
    check(len(profiles) == 3 * 50, f"profiles.csv: 50 bins for each of 3 snapshots ({len(profiles)} rows)")
    check(all("nan" not in ",".join(row.values()).lower() for row in profiles), "profiles.csv: no NaN text")
    mdot = np.array([float(row["mdot_drift"]) for row in profiles if row["mdot_drift"]])
    want = 2.0 * make_test_run.DISK_MASS * 1e-3 / 3.0
    check(abs(np.median(mdot) / want - 1.0) < 0.1, f"disc: median Mdot {np.median(mdot):.4g} ~ 2 M V / 3 = {want:.4g}")
    j = np.array([(float(row["r_lo"]) + float(row["r_hi"])) / 2 for row in profiles if row["j"]]), \
        np.array([float(row["j"]) for row in profiles if row["j"]])
    check(np.max(np.abs(j[1] / np.sqrt(j[0]) - 1.0)) < 0.02, "disc: j = (G M r)^1/2 on Kepler orbits")


def report_md(run_dir, out_dir):
    """report.md of a run; empty when report.py failed."""
    res = run(REPORT, run_dir, "--out", out_dir)
    if not check(res.returncode == 0, f"report.py {os.path.basename(run_dir)} exits 0"):
        print(res.stderr)
        return ""
    return open(os.path.join(out_dir, "report.md"), encoding="utf-8").read()


def test_ring_rule_in_reports(tmp):
    """An older ring file started from a file is not a ring run; Header Problem "ring" overrides that."""
    run_dir = os.path.join(tmp, "from_file")
    if not make_run(run_dir, "--taus", "0.036,0.054", "--no-diagnostics"):
        return
    for path in sorted(os.listdir(run_dir)):
        with h5py.File(os.path.join(run_dir, path), "r+") as f:
            f["Parameters"].attrs["problem.initial_conditions"] = np.bytes_(b"start.hdf5")
    md = report_md(run_dir, os.path.join(tmp, "from_file_out"))
    check("Accuracy against" not in md and "Not a ring run" in md,
          "ring attributes, no Problem, problem.initial_conditions set: reported as a disc")
    for path in sorted(os.listdir(run_dir)):
        with h5py.File(os.path.join(run_dir, path), "r+") as f:
            f["Header"].attrs["Problem"] = np.bytes_(b"ring")
    md = report_md(run_dir, os.path.join(tmp, "problem_ring_out"))
    check("Accuracy against" in md and "τ*/τ" in md, "Header Problem = ring: reported as a ring")


def test_no_diagnostics(tmp):
    run_dir = os.path.join(tmp, "nodiag")
    if not make_run(run_dir, "--no-diagnostics", "--taus", "0.018,0.054"):
        return
    res = run(REPORT, run_dir)
    out_dir = os.path.join(run_dir, "report")
    if not check(res.returncode == 0, "report.py without diagnostics.csv exits 0 (default --out DIR/report)"):
        print(res.stderr)
        return
    for name, size in {**RING_FIGURES, **maps_of(2)}.items():
        check_figure(os.path.join(out_dir, name), size)
    for name in (*DIAG_FIGURES, *SCALING_FIGURES):
        check(not os.path.exists(os.path.join(out_dir, name)), f"no {name} without its CSV")
    md = check_report_md(out_dir, RING_FIGURES)
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
    test_ring_measures()
    test_ring_rule()
    test_render()
    with tempfile.TemporaryDirectory(prefix="sphdisk_report_test_") as tmp:
        test_full_run(tmp)
        test_disc_run(tmp)
        test_ring_rule_in_reports(tmp)
        test_no_diagnostics(tmp)
        test_errors(tmp)
    return check.exit_code("report")


if __name__ == "__main__":
    sys.exit(main())
