// Analytic solution of the viscously spreading ring (Pringle 1981; Lynden-Bell & Pringle 1974),
// as used for the SPH accretion-disc test of P98 section 5.1 (eqs. 10-12). See
// docs/physics.md section 4 for the code-unit conventions (G = M = 1).
#pragma once

namespace sphdisk {

// Switch point between the power series (z < kScaledBesselSwitch) and the Hankel asymptotic
// expansion (z >= kScaledBesselSwitch) in scaled_bessel_i. Both branches reach ~1e-15 relative
// accuracy here for |nu| <= 3 (docs/physics.md sec. 4); exposed so tests can probe continuity.
inline constexpr double kScaledBesselSwitch = 25.0;

// e^{-z} I_nu(z) for real order nu (negative orders like -3/4 included) and z >= 0.
// Power series for small z, Hankel asymptotic expansion for large z (docs/physics.md sec. 4).
// Accurate to ~2e-15 relative for |nu| <= 3 and z in [1e-6, 1e5] (validated against mpmath),
// except next to the zeros that I_nu has for non-integer nu < -1, where only absolute accuracy holds.
// Returns the limit at z = 0 (1 for nu = 0, 0 for nu > 0 or negative integers, otherwise an
// infinity with the sign of Gamma(nu + 1)), NaN for z < 0 or NaN input. Not validated for
// orders |nu| >~ 5, where the Hankel expansion at z = 25 loses accuracy.
// Does NOT use std::cyl_bessel_i (throws for negative order and overflows for z >~ 710).
double scaled_bessel_i(double nu, double z);

// Analytic solution of the viscously spreading ring (P98 eqs. 10-12), all in code units
// (G = M = 1). Initial condition (eq. 10): Sigma_0 = m/(2 pi r0) delta(r - r0).
// All member functions require tau > 0 and r >= 0 and return NaN otherwise.
struct RingSolution {
  double disc_mass;    // m
  double ring_radius;  // r0
  double viscosity;    // nu (kinematic, constant)

  double tau_of_time(double t) const;    // tau = 12 nu t / r0^2
  double time_of_tau(double tau) const;  // t = tau r0^2 / (12 nu)

  // Eq. 11 with exponential scaling:
  //   Sigma = m/(pi r0^2 tau) x^{-1/4} exp(-(1-x)^2/tau) Ĩ_{1/4}(2x/tau),  x = r/r0.
  // Finite at r = 0 (returns the limit m/(pi r0^2 tau^{5/4} Gamma(5/4)) e^{-1/tau}).
  double surface_density(double r, double tau) const;

  // Eq. 12: v_r = 6 nu/(r0 tau) [x - Ĩ_{-3/4}(z)/Ĩ_{1/4}(z)],  z = 2x/tau.
  // Behaves like -3 nu/(2 r) as r -> 0 and returns -infinity at r = 0.
  double radial_velocity(double r, double tau) const;

  // integral_0^r 2 pi r' Sigma(r', tau) dr' by adaptive Gauss-Kronrod quadrature
  // (accurate to ~1e-13 relative). NOTE: as r -> infinity this tends to m - accreted_mass(tau),
  // not to m: the I_{1/4} solution has zero torque at r = 0 and mass flows into the centre.
  double enclosed_mass(double r, double tau) const;

  // Mass that has flowed through r = 0 by viscous time tau. Near the origin v_r -> -3 nu/(2 r)
  // (eq. 12), so the inflow rate is Mdot = -2 pi r Sigma v_r -> 3 pi nu Sigma(0, tau); with
  // Sigma(0) from eq. 11 and dt = r0^2 dtau/(12 nu), integrating over tau gives
  //   accreted = m Gamma(1/4, 1/tau)/Gamma(1/4) = m Q(1/4, 1/tau)   (regularized upper incomplete
  // gamma). It is 1e-26 m at tau = 0.018, 6.4e-7 m at tau = 0.09 and 1.9e-5 m at tau = 0.126.
  // Mass conservation: enclosed_mass(infinity, tau) + accreted_mass(tau) = m.
  double accreted_mass(double tau) const;

  // Area-weighted mean of Sigma over the annulus [r_in, r_out]:
  //   (integral_{r_in}^{r_out} Sigma 2 pi r dr) / (pi (r_out^2 - r_in^2)).
  // Integrates directly over the annulus (no cancellation between two enclosed masses).
  // Returns Sigma(r_in) when r_out == r_in; NaN when r_out < r_in.
  double annulus_mean_surface_density(double r_in, double r_out, double tau) const;
};

}  // namespace sphdisk
