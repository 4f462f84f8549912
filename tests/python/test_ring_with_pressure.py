#!/usr/bin/python3
"""tools/ring_with_pressure.py, the one-dimensional ring with pressure, against what it must give:
- no pressure: the analytic ring (P98 eq. 11) at every output, tau*/tau = 1 to the fit's grid
  step of 0.0005, and the mass kept (the grid's ends are closed);
- with pressure: mass kept, and a departure from the analytic rate that grows as (H/R)^2, the
  order of the pressure's share of the rotation (v_phi^2 = G M / r + (r / Sigma) dP/dr): halving H/R
  from 0.02 divides it by 4, raising it to 0.03 multiplies it by 2.25, within 10% (the next order)
  and the fit's grid step.
"""
import math
import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
sys.path.insert(0, str(ROOT / "tools"))
sys.dont_write_bytecode = True  # no tools/__pycache__ in the work tree
from checklist import summarise  # noqa: E402
import ring_with_pressure as rp  # noqa: E402

OUTPUTS = [0.054, 0.09, 0.126]
GRID_STEP = 0.0005  # the fit's tau grid, in units of tau


def mass(r, dr, sigma):
    return float(np.sum(2.0 * math.pi * r * sigma * dr))


def main():
    checks = []
    departures = {}
    for hr in (0.0, 0.01, 0.02, 0.03):
        r, dr, sigmas = rp.evolve(hr, 0.25, 0.018, OUTPUTS, 4)
        rates = [rp.rate(r, dr, sigma, tau) for tau, sigma in zip(OUTPUTS, sigmas)]
        start = mass(r, dr, rp.Ring(tau=0.018, mass=1.0, r0=1.0, nu=None).sigma(r))
        drift = abs(mass(r, dr, sigmas[-1]) / start - 1.0)
        checks.append((f"H/R {hr}: mass kept to {drift:.1e} (< 1e-10)", drift < 1e-10))
        if hr == 0.0:
            checks.append((f"no pressure: tau*/tau {rates} all 1 within {GRID_STEP}",
                           all(abs(x - 1.0) <= GRID_STEP + 1e-12 for x in rates)))
        departures[hr] = 1.0 - rates[1]
    checks.append((f"pressure slows the ring: 1 - tau*/tau at 0.09 = {departures[0.02]:.4f} at H/R 0.02 (> 0.005)",
                   departures[0.02] > 0.005))
    for hr, factor in ((0.01, 0.25), (0.03, 2.25)):
        expected = factor * departures[0.02]
        tolerance = factor * 0.1 * departures[0.02] + GRID_STEP
        checks.append((f"the departure grows as (H/R)^2: {departures[hr]:.4f} at H/R {hr}, {expected:.4f} expected "
                       f"(+- {tolerance:.4f})", abs(departures[hr] - expected) <= tolerance))
    return summarise("ring_with_pressure", checks)


if __name__ == "__main__":
    sys.exit(main())
