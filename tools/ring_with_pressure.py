#!/usr/bin/python3
"""The spreading ring with pressure, as a one-dimensional viscous disc: the rate the analytic
(pressureless) solution cannot give, to compare SPH rings with an equation of state against.

A ring with a locally isothermal pressure P = Sigma c_s^2, c_s = c0 (r/r0)^-q, rotates with
v_phi^2 = G M / r + (r / Sigma) dP/dr (radial balance; the 3D torus's vertically integrated P is the
same to O((H/R)^2) in smooth terms). Inside the ring's peak the pressure gradient makes it spin
faster than Kepler, outside slower, by ~(H/R)^2 / (width / r)^2: the shear r dOmega/dr steepens
and dj/dr flattens, which alone would speed the spreading; but as the ring widens its pressure
support relaxes, j falls inside the peak and rises outside, and that change of j (the Sigma dj/dt
below) holds the gas back by more. Net, pressure slows the ring by an amount set by H/R and the
ring's width alone (tau*/tau 0.991 at H/R 0.02 and tau 0.09). This evolves the thin-disc equations
    dSigma/dt = -(1/r) d(r Sigma v_r)/dr,
    Sigma (dj/dt + v_r dj/dr) = (1/r) d(nu Sigma r^3 dOmega/dr)/dr,   j = r v_phi,
(conservative finite volumes, explicit steps; dj/dt, which depends on dSigma/dt through the
pressure term, is solved for with the fluxes, a tridiagonal system) from the analytic ring at
tau_start, and fits its surface density with the pressureless profile exactly as `sphdisk analyze`
does (tools/ring_model.py: 50 annuli over 0.05-2.05 r0, annulus-mass L1, tau* on a 0.0005 tau grid).
Without pressure the model returns tau*/tau = 1 to the fit's grid step (tests/python/
test_ring_with_pressure.py); 4 and 8 grid cells per annulus agree to 0.001.

Usage: ring_with_pressure.py [--q Q] [--tau-start T] [--cells-per-bin K] H/R [H/R ...]
  prints tau*/tau at tau = 0.054, 0.09 and 0.126 for each H/R at r0 (0: no pressure).
Code units G = M = r0 = 1, nu = 1/12 (so that tau = 12 nu t / r0^2 is the time).
"""
import argparse
import os
import sys

import numpy as np
from scipy.linalg import solve_banded

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ring_model import BIN_RANGE, N_BINS, Ring, fit_tau  # noqa: E402

NU = 1.0 / 12.0
R_IN, R_OUT = 0.05, 4.0   # grid (from the analysis's inner edge, the accretion radius); empty beyond it


def rotation(sigma, rf, cs2f, dr):
    """v_phi on the cell faces rf (all n + 1; empty cells beyond the grid) of the pressure-supported
    ring, and dj/dSigma of its two cells (the pressure term of j = r v_phi depends on Sigma's
    slope). Keplerian where Sigma vanishes; the face value of dP/dr keeps the stencil compact."""
    padded = np.concatenate(([0.0], sigma, [0.0]))
    below, above = padded[:-1], padded[1:]
    mean = 0.5 * (above + below)
    resolved = mean > 1e-30 * mean.max()  # Keplerian in the empty far wings, where the ratio is 0/0
    safe = np.where(resolved, mean, 1.0)
    slope = (above - below) / dr
    support = np.where(resolved, cs2f * slope / safe + np.gradient(cs2f, dr), 0.0)  # (1/Sigma) dP/dr
    vphi = np.sqrt(np.maximum(1.0 / rf + rf * support, 0.05 / rf))  # Rayleigh-safe where nearly empty
    djdq = np.where(resolved, rf**2 / (2.0 * vphi), 0.0)  # j = r v_phi, v_phi^2 = 1/r + r Q
    dj_dabove = djdq * cs2f * (1.0 / dr - 0.5 * slope / safe) / safe
    dj_dbelow = djdq * cs2f * (-1.0 / dr - 0.5 * slope / safe) / safe
    return vphi, dj_dabove, dj_dbelow


def evolve(aspect_ratio, q, tau_start, outputs, cells_per_bin):
    """Sigma at each output tau, on the grid's cell centres; returns (centres, dr, [Sigma, ...])."""
    dr = (BIN_RANGE[1] - BIN_RANGE[0]) / N_BINS / cells_per_bin
    n = int(round((R_OUT - R_IN) / dr))
    r = R_IN + dr * (np.arange(n) + 0.5)
    rf = R_IN + dr * np.arange(n + 1)
    cs2f = aspect_ratio**2 * rf ** (-2.0 * q)  # c_s^2 in units of v_Kepler(r0)^2, on the faces
    sigma = Ring(tau=tau_start, mass=1.0, r0=1.0, nu=None).sigma(r)
    # Explicit limits: the diffusion's dr^2 / (2 * 3 nu), and the pressure's: Omega depends on dSigma/dr,
    # so the flux holds a third derivative and Sigma a fourth, dSigma/dt ~ -nu c_s^2 d^4 Sigma/dr^4.
    dt = min(0.2 * dr**2 / (3.0 * NU), 0.05 * dr**4 / (NU * max(cs2f.max(), 1e-30)))
    t, found = tau_start, []
    inner, outer = rf[1:-1], slice(1, n)  # the interior faces carry the fluxes F = Sigma v_r
    for tau_out in sorted(outputs):
        while t < tau_out - 1e-12:
            step = min(dt, tau_out - t)
            vphi, a, b = rotation(sigma, rf, cs2f, dr)
            omega, j = vphi / rf, vphi * rf
            torque = NU * sigma * r**3 * (omega[1:] - omega[:-1]) / dr  # nu Sigma r^3 dOmega/dr, cells
            jc = 0.5 * (j[1:] + j[:-1])
            djdr = np.concatenate(([1.0], np.maximum((jc[1:] - jc[:-1]) / dr, 1e-3), [1.0]))
            # Face f: dj/dr F_f + Sigma_f dj_f/dt = (1/r) dG/dr, with dj_f/dt = a_f dSigma_f/dt +
            # b_f dSigma_(f-1)/dt and dSigma_i/dt = -(r F)' / r: tridiagonal in F, solved implicitly
            # (lagging dj/dt is unstable on the grid's short waves).
            sf = np.concatenate(([0.0], 0.5 * (sigma[1:] + sigma[:-1]), [0.0]))
            rhs = (torque[1:] - torque[:-1]) / dr / inner
            upper = -sf[outer] * a[outer] * rf[2:] / (r[1:] * dr)
            diag = djdr[outer] + sf[outer] * (a[outer] * inner / (r[1:] * dr) - b[outer] * inner / (r[:-1] * dr))
            lower = sf[outer] * b[outer] * rf[:-2] / (r[:-1] * dr)
            bands = np.zeros((3, n - 1))
            bands[0, 1:], bands[1], bands[2, :-1] = upper[:-1], diag, lower[1:]
            flux = solve_banded((1, 1), bands, rhs)
            rflux = np.concatenate(([0.0], inner * flux, [0.0]))  # closed ends: the mass there is negligible
            sigma = np.maximum(sigma - step * (rflux[1:] - rflux[:-1]) / (r * dr), 0.0)
            t += step
        found.append(sigma.copy())
    return r, dr, found


def annulus_means(r, dr, sigma):
    """Area-weighted mean Sigma over the analysis annuli (grid cells nest in the bins exactly)."""
    lo = np.searchsorted(r, BIN_RANGE[0])
    per = int(round((BIN_RANGE[1] - BIN_RANGE[0]) / N_BINS / dr))
    s = sigma[lo:lo + per * N_BINS].reshape(N_BINS, per)
    w = r[lo:lo + per * N_BINS].reshape(N_BINS, per)
    return np.sum(s * w, axis=1) / np.sum(w, axis=1)


def rate(r, dr, sigma, tau):
    """tau*/tau of the model's Sigma at viscous time tau, fitted as `sphdisk analyze` fits a ring."""
    edges = np.linspace(BIN_RANGE[0], BIN_RANGE[1], N_BINS + 1)
    tau_fit, _ = fit_tau(Ring(tau=tau, mass=1.0, r0=1.0, nu=None), edges, annulus_means(r, dr, sigma))
    return tau_fit / tau


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("aspect_ratios", type=float, nargs="+", metavar="H/R")
    ap.add_argument("--q", type=float, default=0.25, help="sound-speed index, c_s ~ r^-q (default 0.25)")
    ap.add_argument("--tau-start", type=float, default=0.018)
    ap.add_argument("--cells-per-bin", type=int, default=4, help="grid cells per analysis annulus (default 4; 8 agrees to 0.001)")
    args = ap.parse_args()
    outputs = [0.054, 0.09, 0.126]
    print("H/R at r0  q     " + "  ".join(f"tau*/tau at {t:.3f}" for t in outputs))
    for hr in args.aspect_ratios:
        r, dr, sigmas = evolve(hr, args.q, args.tau_start, outputs, args.cells_per_bin)
        rates = [rate(r, dr, sigma, tau) for tau, sigma in zip(outputs, sigmas)]
        print(f"{hr:<10g}  {args.q:<4g}  " + "  ".join(f"{x:17.4f}" for x in rates))


if __name__ == "__main__":
    main()
