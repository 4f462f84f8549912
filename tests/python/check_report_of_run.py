#!/usr/bin/python3
"""`sphdisk report DIR` on a real ring run: every figure exists as a non-blank PNG of the expected size
with its PDF, and the summary's verdict figures and the binned guiding-centre drift agree with
`sphdisk analyze` of the last snapshot.

Usage: check_report_of_run.py SPHDISK RUN_DIR
"""
import csv
import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib.image as mpimg
import numpy as np

# Pixel sizes at 300 dpi of figures one (3.5 in) or two (7 in) columns wide.
EXPECTED = {
    "fig5_positions.png": (1050, 1050),
    "fig6_sigma.png": (1050, 780),
    "fig7_vr.png": (2100, 840),
    "fig8_binned_sigma.png": (1050, 780),
    "error_vs_time.png": (1050, 780),
    "accreted_mass.png": (1050, 780),
    "conservation.png": (2100, 1500),
    "sigma_map_000.png": (1050, 840),
}


class Tally:
    def __init__(self):
        self.passed = self.failed = 0

    def __call__(self, ok, what):
        print(("ok   " if ok else "FAIL ") + what)
        self.passed, self.failed = self.passed + bool(ok), self.failed + (not ok)


def figure_ok(path, size):
    if not (path.exists() and path.stat().st_size > 0 and path.with_suffix(".pdf").exists()):
        return False
    img = mpimg.imread(path)
    pdf_ok = path.with_suffix(".pdf").read_bytes()[:5] == b"%PDF-"
    return (img.shape[1], img.shape[0]) == size and img.std() > 0 and pdf_ok


def analyze(sphdisk, snapshot):
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "analysis.json"
        subprocess.run([sphdisk, "analyze", str(snapshot), "--json", str(out)], check=True, capture_output=True)
        return json.loads(out.read_text())


def check_against_analyze(check, sphdisk, run, md):
    """The summary's tau*/tau, annulus-mass L1 and sampling floor, and profiles.csv's binned drift, as
    `sphdisk analyze` forms them."""
    last = sorted(run.glob("snapshot_*.hdf5"))[-1]
    ref = analyze(sphdisk, last)
    m = re.search(r"τ\*/τ = ([0-9.]+)", md)
    rate = ref["tau_fit"] / ref["tau"]  # one step of the fine scan (0.0005) apart at most: quadratures differ
    check(m is not None and abs(float(m.group(1)) - rate) <= 0.0011,
          f"summary τ*/τ {m and m.group(1)} = analyze's {rate:.4f}")
    m = re.search(r"τ\*/τ - 1 = ([-+][0-9.]+) = ([0-9.]+) sd of its sampling scatter ([0-9.]+): (within|beyond) "
                  r"the noise of ([0-9]+) particles", md)
    sd = ref["rate_sampling_sd"]
    check(m is not None and abs(float(m.group(3)) - sd) <= 1e-4 and int(m.group(5)) == ref["particles"]
          and abs(float(m.group(2)) - abs(float(m.group(1))) / sd) <= 0.051
          and m.group(4) == ("within" if float(m.group(2)) <= 2.0 else "beyond"),
          f"summary's rate departure in sd of analyze's sampling scatter {sd:.4f}: {m and m.group(0)}")
    m = re.search(r"Annulus-mass L1 ([0-9.]+) = [0-9.]+ × its sampling floor ([0-9.]+)", md)
    check(m is not None and abs(float(m.group(1)) - ref["mass_sigma_l1"]) <= 1e-3
          and abs(float(m.group(2)) - ref["sampling_floor"]) <= 1e-3,
          f"summary annulus-mass L1 and floor {m and m.groups()} = analyze's "
          f"({ref['mass_sigma_l1']:.4f}, {ref['sampling_floor']:.4f})")
    with open(run / "report" / "profiles.csv", newline="") as fh:
        rows = [r for r in csv.DictReader(fh) if r["snapshot"] == last.name]
    ours = np.array([float(r["vr_drift"]) if r["vr_drift"] else 0.0 for r in rows])
    theirs = np.array([b["vr_drift"] if b["count"] else 0.0 for b in ref["bins"]])
    check(len(ours) == len(theirs) and np.allclose(ours, theirs, rtol=1e-6, atol=1e-12 * np.max(np.abs(theirs))),
          "profiles.csv binned guiding-centre drift = analyze's v_r_drift")


def main():
    sphdisk, run = sys.argv[1], Path(sys.argv[2])
    subprocess.run([sphdisk, "report", str(run)], check=True)
    check = Tally()
    md = (run / "report" / "report.md").read_text()
    for name, size in EXPECTED.items():
        check(figure_ok(run / "report" / name, size), f"{name} ({size[0]}x{size[1]} px) and its PDF")
        check(f"]({name})" in md, f"report.md links {name}")
    check(md.find("## Summary") < md.find("## Figures") < md.find("## Details") and md.find("## Summary") > 0,
          "report.md: summary, figures, details")
    check_against_analyze(check, sphdisk, run, md)
    print(f"report of run: {check.passed} passed, {check.failed} failed")
    return 1 if check.failed else 0


if __name__ == "__main__":
    sys.exit(main())
