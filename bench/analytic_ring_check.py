#!/usr/bin/python3
"""The analytic ring solution (P98 eqs. 10-12, as bench/fit_viscous_time.py and `sphdisk analyze`
evaluate it) against a finite-difference solution of the same diffusion equation,
d Sigma / d tau = (1 / 4x) d/dx [x^1/2 d/dx (Sigma x^1/2)] (tau = 12 nu t / r0^2, x = r / r0), started
from the analytic profile at tau = 0.018 (2001 points on 0.001-4 r0, explicit steps of 0.2 dx^2, zero
Sigma at both ends). Prints both and their ratio at radii from the inner wing to the outer one at
tau = 0.09 and 0.126, so that a deficit of particles in the wings can be told from an error in the
analytic profile (docs/validation.md, "The mixed gradient correction").

Usage: bench/analytic_ring_check.py
"""
import numpy as np

from fit_viscous_time import sigma


def main():
    x = np.linspace(1e-3, 4.0, 2001)
    dx = x[1] - x[0]
    s = sigma(x, 0.018, 1.0)
    tau, step = 0.018, 0.2 * dx * dx
    for end in (0.09, 0.126):
        while tau < end - 1e-15:
            dt = min(step, end - tau)
            f = s * np.sqrt(x)
            flux = np.sqrt(0.5 * (x[1:] + x[:-1])) * (f[1:] - f[:-1]) / dx  # at the half points
            rate = np.zeros_like(s)
            rate[1:-1] = (flux[1:] - flux[:-1]) / dx / (4 * x[1:-1])
            s = s + dt * rate
            s[0] = s[-1] = 0.0
            tau += dt
        exact = sigma(x, end, 1.0)
        for r in (0.3, 0.5, 1.0, 1.5, 1.6, 1.7, 1.8, 1.9):
            k = int(round((r - x[0]) / dx))
            print(f"tau {end}: r {r}: finite differences {s[k]:.6e}, analytic {exact[k]:.6e}, ratio {s[k] / exact[k]:.5f}")


if __name__ == "__main__":
    main()
