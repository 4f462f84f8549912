#!/usr/bin/python3
"""`sphdisk report DIR` on a real run: every ring figure exists as a non-blank PNG of the expected size.

Usage: check_report_of_run.py SPHDISK RUN_DIR
"""
import subprocess
import sys
from pathlib import Path

import matplotlib.image as mpimg

EXPECTED = {
    "fig5_positions.png": (640, 640),
    "fig6_sigma.png": (640, 480),
    "fig7_vr.png": (640, 480),
    "fig8_binned_sigma.png": (640, 480),
    "error_vs_time.png": (640, 480),
    "conservation.png": (640, 480),
}


def main():
    sphdisk, run = sys.argv[1], Path(sys.argv[2])
    subprocess.run([sphdisk, "report", str(run)], check=True)
    passed = failed = 0
    for name, (w, h) in EXPECTED.items():
        path = run / "report" / name
        ok = path.exists() and path.stat().st_size > 0
        if ok:
            img = mpimg.imread(path)
            ok = img.shape[1] == w and img.shape[0] == h and img.std() > 0
        print(("ok   " if ok else "FAIL ") + name)
        passed, failed = passed + ok, failed + (not ok)
    md = (run / "report" / "report.md").read_text()
    for name in EXPECTED:
        ok = name in md
        passed, failed = passed + ok, failed + (not ok)
    print(f"report of run: {passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
