"""The analytic viscous ring (P98 eqs. 11-12, code units G = M = 1) and the ring measures of
docs/physics.md sec. 4 "Diagnostics", as `sphdisk analyze` forms them (src/app/ring_analysis.cpp):
annulus-mass L1, its sampling floor, the best-fit viscous time tau* and the verdict.
"""
import math
from dataclasses import dataclass

import numpy as np
from scipy.special import ive

BIN_RANGE = (0.05, 2.05)  # radial bins of the comparison, in units of r0
N_BINS = 50               # as `sphdisk analyze` (P98 Fig. 8)
SCATTER_CUT = 0.01        # per-particle scatter uses Sigma_ana > 1% of the analytic peak
ANNULUS_SAMPLES = 100     # midpoint-rule samples of the analytic annulus mean (relative error ~1e-6)
RATE_TOLERANCE = 0.02     # verdict: |tau*/tau - 1| within this
FLOOR_FACTOR = 1.5        # verdict: annulus-mass L1 within this many sampling floors
NOISE_SDS = 2.0           # verdict: a rate within this many sd of its sampling scatter is within the noise


@dataclass
class Ring:
    """Analytic spreading ring (P98 eqs. 11-12) at viscous time tau; code units."""
    tau: float
    mass: float
    r0: float
    nu: float | None

    def sigma(self, r, tau=None):
        """Surface density at radii r (at viscous time tau, default the ring's own)."""
        tau = self.tau if tau is None else tau
        x = np.asarray(r, dtype=float) / self.r0
        z = 2.0 * x / tau
        return (self.mass / (math.pi * self.r0**2 * tau) * x**-0.25
                * np.exp(-(1.0 - x) ** 2 / tau) * ive(0.25, z))

    def vr_over_nu(self, r):
        """Radial velocity divided by the kinematic viscosity nu."""
        x = np.asarray(r, dtype=float) / self.r0
        z = 2.0 * x / self.tau
        return 6.0 / (self.r0 * self.tau) * (x - ive(-0.75, z) / ive(0.25, z))

    def peak_sigma(self):
        return float(np.nanmax(self.sigma(self.r0 * np.linspace(1e-3, 3.0, 6000))))


def is_ring_run(header, params):
    """A ring run: Header `Problem` is "ring"; without that attribute (older files, or files made by
    hand), where the Header has the ring's positive ViscousTime, KinematicViscosity and DiskMass and
    the run did not start from a file (non-empty /Parameters problem.initial_conditions), as
    `sphdisk analyze` decides (src/app/disc_profiles.cpp, is_ring_snapshot)."""
    problem = header.get("Problem")
    if problem is not None:
        return (problem.decode() if isinstance(problem, bytes) else str(problem)).strip().strip('"') == "ring"
    if not all(float(header.get(k, 0)) > 0 for k in ("ViscousTime", "KinematicViscosity", "DiskMass")):
        return False
    start_file = (params or {}).get("problem.initial_conditions")
    return not (start_file is not None and str(start_file).strip().strip('"'))


def snapshot_tau(header):
    """Viscous time of a snapshot: ViscousTime, else 12 nu t / r0^2, else None."""
    if "ViscousTime" in header:
        return float(header["ViscousTime"])
    nu, r0, t = header.get("KinematicViscosity"), header.get("RingRadius"), header.get("Time")
    if nu is None or r0 is None or t is None or r0 == 0:
        return None
    return 12.0 * float(nu) * float(t) / float(r0) ** 2


def ring_from_header(header):
    """Ring model for a snapshot header, or None when it lacks positive DiskMass, RingRadius and tau."""
    mass, r0 = header.get("DiskMass"), header.get("RingRadius")
    nu = header.get("KinematicViscosity")
    tau = snapshot_tau(header)
    if mass is None or r0 is None or tau is None or tau <= 0 or mass <= 0 or r0 <= 0:
        return None
    return Ring(float(tau), float(mass), float(r0), float(nu) if nu else None)


def annulus_mean_analytic(ring, edges, tau=None, samples=ANNULUS_SAMPLES):
    """Area-weighted analytic mean of Sigma over each annulus (midpoint rule in r)."""
    lo, hi = edges[:-1, None], edges[1:, None]
    rr = lo + (hi - lo) * (np.arange(samples) + 0.5) / samples
    return np.sum(ring.sigma(rr, tau) * rr, axis=1) / np.sum(rr, axis=1)


def l1_against(mass_sigma, analytic):
    """sum_b |Sigma_mass,b - Sigma_ann,b| / sum_b Sigma_ann,b over all bins."""
    denom = float(np.sum(analytic))
    return float(np.sum(np.abs(mass_sigma - analytic)) / denom) if denom > 0 else None


def sampling_floor(ring, edges, particles):
    """Expected annulus-mass L1 of `particles` drawn at random from the exact profile: bin counts are
    binomial (N, p_b) and E|n_b - N p_b| ~ (2 N p_b (1 - p_b) / pi)^(1/2) particles of mass M_bins / N."""
    ana = annulus_mean_analytic(ring, edges)
    area = np.pi * (edges[1:] ** 2 - edges[:-1] ** 2)
    bins_mass = float(np.sum(ana * area))
    if bins_mass <= 0 or particles <= 0 or np.sum(ana) <= 0:
        return None
    share = ana * area / bins_mass
    spread = np.sqrt(2.0 * particles * share * (1.0 - share) / np.pi) * (bins_mass / particles) / area
    return float(np.sum(spread) / np.sum(ana))


def fit_tau(ring, edges, mass_sigma):
    """tau* minimising the annulus-mass L1: 0.5-1.5 tau in steps of 0.005 tau, then +-0.005 tau around
    the best in steps of 0.0005 tau (the first minimum of each scan). Returns (tau*, L1 at tau*)."""
    def best(lo, hi, steps):
        taus = lo + (hi - lo) * np.arange(steps + 1) / steps
        l1 = [l1_against(mass_sigma, annulus_mean_analytic(ring, edges, t)) for t in taus]
        k = int(np.argmin(l1))
        return float(taus[k]), l1[k]
    coarse, _ = best(0.5 * ring.tau, 1.5 * ring.tau, 200)
    return best(coarse - 0.005 * ring.tau, coarse + 0.005 * ring.tau, 20)


def verdict(rate, l1_mass, floor):
    """(spreading rate within RATE_TOLERANCE, mass profile within FLOOR_FACTOR sampling floors)."""
    rate_ok = rate is not None and abs(rate - 1.0) <= RATE_TOLERANCE
    noise_ok = bool(floor) and l1_mass is not None and l1_mass <= FLOOR_FACTOR * floor
    return rate_ok, noise_ok
