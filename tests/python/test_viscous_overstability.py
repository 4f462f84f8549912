#!/usr/bin/python3
"""tools/viscous_overstability.py against what the shearing-sheet equations give by hand.

- no viscosity: no growth, and the waves oscillate at (Omega^2 + k^2 c^2)^1/2, the epicyclic
  frequency of a pressure-supported Keplerian disc;
- long waves grow at (2/3 - r) nu k^2 / 2, r = nu_bulk / nu (the cubic's roots near +-i Omega to
  first order in k^2), so they grow below r = 2/3 and decay above;
- the whole band of wavelengths is stable from r = 2/3 on and unstable just below it;
- the ring configurations: configs/ring.toml (the paper's nu_bulk = 0) is overstable,
  configs/ring_cold.toml, with nu_bulk = nu, is not.
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
import viscous_overstability as vo  # noqa: E402


def main():
    checks = []
    nu, c = 4.8e-5, 0.005
    checks.append(("no viscosity: no growth", abs(vo.growth_rate(60.0, 0.0, 0.0, c)) < 1e-12))
    frequency = np.abs(vo.rates(60.0, 0.0, 0.0, c).imag).max()
    checks.append(("no viscosity: oscillation at (Omega^2 + k^2 c^2)^1/2",
                   abs(frequency - math.sqrt(1 + 60.0**2 * c * c)) < 1e-12))
    k = 2.0  # a wave of 3 r0: nu k^2 = 2e-4 Omega, in the long-wave limit
    for r in (0.0, 0.5, 1.0):
        expected = (2.0 / 3.0 - r) * nu * k * k / 2
        got = vo.growth_rate(k, nu, r * nu, c)
        checks.append((f"long waves, nu_bulk/nu = {r}: growth {got:.4e} = (2/3 - r) nu k^2 / 2 = {expected:.4e}",
                       abs(got - expected) < 0.01 * nu * k * k))
    lengths = np.geomspace(1e-3, 1.0, 300)
    for r, stable in ((0.6, False), (2.0 / 3.0, True), (1.0, True)):
        _, _, band = vo.scan(nu, r * nu, c, lengths)
        checks.append((f"nu_bulk/nu = {r:.3f}: {'stable' if stable else 'a growing band'} at 0.001-1 r0",
                       (band is None) == stable and vo.stable_for_all_wavelengths(nu, r * nu) == stable))
    paper = vo.set_up(vo.read_config(ROOT / "configs/ring.toml", []))
    rate, fastest, band = vo.scan(paper[0], paper[1], paper[2], lengths)
    checks.append((f"configs/ring.toml, the paper's: overstable ({rate:.3f} Omega at {fastest:.3f} r0)",
                   band is not None and 0.03 < rate < 0.05))
    cold = vo.set_up(vo.read_config(ROOT / "configs/ring_cold.toml", []))
    checks.append(("configs/ring_cold.toml: no growing wave", vo.scan(cold[0], cold[1], cold[2], lengths)[2] is None))
    x16 = vo.set_up(vo.read_config(ROOT / "configs/ring_cold.toml", ["physics.viscosity=4.8e-7"]))
    checks.append(("configs/ring_cold.toml at 16x the viscosity: no growing wave", vo.scan(x16[0], x16[1], x16[2], lengths)[2] is None))
    return summarise("viscous overstability", checks)


if __name__ == "__main__":
    sys.exit(main())
