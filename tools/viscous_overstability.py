#!/usr/bin/python3
"""Viscous overstability of a ring or disc set-up (docs/physics.md sec. 4, "Viscous overstability"): the growth rate of
axisymmetric waves in the local shearing sheet of a Keplerian, isothermal, Navier-Stokes disc at
the ring radius r0, from the run's own viscosities and sound speed.

The linearised equations (perturbations ~ exp(s t + i k x), x radial, surface density Sigma(1 + d),
shear nu and bulk nu_b kinematic viscosities constant, eq. 7's trace factor 2/3):
    s d = -i k u
    s u = 2 Omega v - i k c^2 d - (4/3 nu + nu_b) k^2 u
    s v = -(Omega / 2) u - nu k^2 v - (3/2) i k Omega nu d
(the last term: the perturbed mass carries the background's viscous stress -(3/2) Sigma nu Omega).
Their cubic s^3 + A s^2 + B s + C = 0 is stable for every k (Routh-Hurwitz: AB > C) when
    (7/3 + r) (4/3 + r) nu^2 k^4 + (4/3 + r) k^2 c^2 + (r - 2/3) Omega^2 > 0,   r = nu_b / nu,
i.e. for any sound speed once nu_b >= (2/3) nu; with nu_b = 0 waves longer than a few
(nu / Omega)^1/2 or c / Omega grow at up to ~0.04 Omega. Over a run of tau (= 12 nu t / r0^2) the
growth is s Omega t = s (tau_end - tau_start) r0^2 / (12 nu) e-folds (or s t over output.times or
output.orbits).

Usage: tools/viscous_overstability.py CONFIG.toml [--set KEY=VALUE ...]
  CONFIG: a configuration (configs/*.toml) or a run's config.toml; --set as for `sphdisk run`.
"""
import argparse
import math
import sys
import tomllib

import numpy as np

G_CGS, RSUN_CM, MSUN_G = 6.67430e-8, 6.957e10, 1.98841e33


def rates(k, nu, nu_b, c, omega=1.0):
    """The three roots s of the linearised equations at wavenumber k (all in one unit system)."""
    m = np.array([[0, -1j * k, 0],
                  [-1j * k * c * c, -(4.0 / 3.0 * nu + nu_b) * k * k, 2 * omega],
                  [-1.5j * k * omega * nu, -0.5 * omega, -nu * k * k]], dtype=complex)
    return np.linalg.eigvals(m)


def growth_rate(k, nu, nu_b, c, omega=1.0):
    """Largest real part of s at wavenumber k."""
    return float(rates(k, nu, nu_b, c, omega).real.max())


def stable_for_all_wavelengths(nu, nu_b):
    """The Routh-Hurwitz condition at k -> 0, which bounds all k (module docstring)."""
    return nu == 0 or nu_b >= 2.0 / 3.0 * nu


def scan(nu, nu_b, c, lengths):
    """(largest growth rate, its wavelength, [shortest, longest] growing wavelength) over lengths."""
    rates = [growth_rate(2 * math.pi / lam, nu, nu_b, c) for lam in lengths]
    growing = [lam for lam, s in zip(lengths, rates) if s > 1e-12]
    best = int(np.argmax(rates))
    return rates[best], lengths[best], (min(growing), max(growing)) if growing else None


def read_config(path, sets):
    with open(path, "rb") as f:
        cfg = tomllib.load(f)
    for item in sets:
        key, _, value = item.partition("=")
        table, _, name = key.partition(".")
        if not name:
            sys.exit(f"viscous_overstability: --set {item}: give KEY=VALUE with KEY as table.name")
        cfg.setdefault(table, {})[name] = tomllib.loads(f"v = {value}")["v"]
    return cfg


def set_up(cfg):
    """nu, nu_b, c_s at r0 and the run's length, in code units (r0 = G = M = 1, so Omega(r0) = 1;
    physics.alpha_ss: its nu at r0)."""
    problem, physics, output = cfg.get("problem", {}), cfg.get("physics", {}), cfg.get("output", {})
    r0 = problem.get("ring_radius", 1.0) * RSUN_CM
    omega = math.sqrt(G_CGS * physics.get("central_mass", 1.0) * MSUN_G / r0**3)
    to_code = RSUN_CM**2 / (r0 * r0 * omega)  # solar radii^2 / s -> r0^2 Omega(r0)
    nu = physics.get("viscosity", 0.0) * to_code
    c = 0.0
    if physics.get("eos", "none") in ("isothermal", "locally_isothermal"):
        c = physics.get("aspect_ratio", 0.0) or physics.get("sound_speed", 0.0) * 1e5 / (r0 * omega)
    if physics.get("alpha_max", 0.0) > 0 and nu > 0:
        c = max(c, math.sqrt(nu / physics["alpha_max"]))
    if physics.get("alpha_ss", 0.0) > 0:  # nu = alpha c_s H at r0
        nu = physics["alpha_ss"] * c * c
    nu_b = physics.get("bulk_viscosity", 0.0) * to_code + physics.get("bulk_viscosity_ratio", 0.0) * nu
    # The run's length in 1 / Omega(r0) (code time units): output.times, output.orbits or output.tau.
    if output.get("times"):
        length = output["times"][-1]
    elif output.get("orbits"):
        length = output["orbits"][-1] * 2 * math.pi * output.get("orbit_radius", 1.0) ** 1.5
    else:
        taus = output.get("tau", [0.036, 0.054, 0.072, 0.09, 0.126])
        length = (taus[-1] - problem.get("tau_start", 0.018)) / (12 * nu) if nu > 0 else None
    return nu, nu_b, c, length


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("config")
    parser.add_argument("--set", action="append", default=[], dest="sets")
    args = parser.parse_args()
    nu, nu_b, c, length = set_up(read_config(args.config, args.sets))
    if nu <= 0:
        sys.exit("viscous_overstability: the configuration has no shear viscosity (physics.viscosity and physics.alpha_ss are 0)")
    alpha = f"{nu / (c * c):.3g}" if c > 0 else "infinite (no pressure)"
    print(f"at r0: nu = {nu:.4g}, nu_bulk = {nu_b:.4g} r0^2 Omega; H/R = c_s / v_K = {c:.4g}; alpha = nu Omega / c_s^2 = {alpha}")
    lengths = np.geomspace(1e-3, 1.0, 600)
    rate, fastest, band = scan(nu, nu_b, c, lengths)
    if band is None:
        print(f"no growing axisymmetric wave at 0.001-1 r0 (nu_bulk / nu = {nu_b / nu:.3g}; stable for all "
              f"wavelengths from 2/3): {'stable' if stable_for_all_wavelengths(nu, nu_b) else 'growing beyond 1 r0 only'}")
        return
    print(f"overstable: largest growth rate {rate:.4g} Omega at wavelength {fastest:.4g} r0; waves of "
          f"{band[0]:.4g}-{band[1]:.4g} r0 grow (nu_bulk >= 2/3 nu = {2 * nu / 3:.4g} removes them all)")
    if length:
        efolds = rate * length
        print(f"over the run ({length:.4g} / Omega): {efolds:.2f} e-folds, an amplitude factor of {math.exp(efolds):.3g}")


if __name__ == "__main__":
    main()
