#pragma once
// Physical parameters in code units (G = M = r0 = 1 for the ring; see core/units.hpp).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string_view>

#include "core/named_choice.hpp"
#include "core/vec.hpp"
#include "physics/kernels.hpp"

namespace sphdisk {

// The equation of state: none (pressureless, as in the ring test, P98 5.2); isothermal, P = c_s^2 rho
// with one c_s; locally isothermal, P = c_s(R)^2 rho with c_s(R) = c_s0 (R / r0)^-q, R the
// cylindrical radius (Phantom's ieos = 3; docs/physics.md sec. 4); adiabatic, P = (gamma - 1) rho u
// with each particle's evolved internal energy u (Phantom's ieos = 2; the energy equation is then on).
enum class EquationOfState { None, Isothermal, LocallyIsothermal, Adiabatic };

// How eq. 6's divergence of the viscous stress is discretised (physics/forces.hpp):
//   Conservative: sum_j m_j (S_i / rho_j + S_j / rho_i) . grad_i W_ij, as P98 prints it; pair terms
//                 antisymmetric, so linear momentum is conserved to round-off, but a constant stress
//                 gives a force S . sum_j m_j (1/rho_i + 1/rho_j) grad_i W_ij that vanishes only on
//                 ordered particles.
//   Consistent:   (1/rho) div(rho S) = div S + S . grad ln rho, each from differences over the
//                 neighbours with the linear-exact gradient (C_i = M_i^-1):
//                 sum_j V_j [S_j - S_i + S_i ln(rho_j / rho_i)] . C_i grad_i W_ij; exactly zero for a
//                 constant stress and density on any particle set, exact for linear ones. Linear
//                 momentum is conserved only to the discretisation error.
// docs/validation.md ("Why the ring spread too slowly") shows why the default is Consistent.
enum class ViscousForce { Conservative, Consistent };

// Which densities the consistent divergence's S_i ln(rho_j / rho_i) compares (physics/list_sums.hpp):
//   Others:    each without the pair's own two terms, rho_i - m_i W(0, h_i) - m_j W(r_ij, h_i) and
//              the same for j: the density of the surroundings both particles sit in. The summed
//              densities include them, and the nearer particle of a pair, with the wider kernel on
//              the sparse side, raises the sparse density relatively more: the contrast a pair sees,
//              and with it S . grad ln rho, comes out too small by a fraction that does not shrink
//              with N (docs/validation.md, "The density a pair compares").
//   Summation: the summed densities as they are.
//   Scatter:   each particle's density from its neighbours' kernels, rho_s,i = sum_j m_j W(r_ij, h_j)
//              (physics/scatter_density.hpp): the gather sum's bias (kappa/2) h_i^2 lap rho grows
//              without bound in a profile's sparse wings, where h^2 ~ 1/rho; the scatter sum's,
//              (kappa/2) lap(h^2 rho), vanishes in 2D at a fixed neighbour number
//              (docs/validation.md, "A density without the gather bias: the scatter sum").
enum class PairDensity { Others, Summation, Scatter };

// The kernel gradient of the velocity gradient (eq. 8) and of the consistent divergence
// (viscous_stress.hpp, pair_terms.hpp), with V_k = m_k / rho_k and g_ik = grad_i W_ik:
//   None:   g_ik as printed (eq. 8) for the velocity gradient; the consistent divergence keeps C_i.
//   Linear: C_i g_ik with C_i = M_i^-1 (moment_correction.hpp): exact for linear fields.
//   Mixed:  C~_i (g_ik - W_ik e_i), e_i = sum_k V_k g_ik / sum_k V_k W_ik: the gradient of the
//           Shepard-normalised kernel, made exact for linear fields by its own moment matrix C~_i
//           (the mixed correction of Bonet & Lok 1999). Its weights sum to zero over the neighbours,
//           so a particle's own value does not enter its gradient; with Linear it enters as
//           -C_i sum_k V_k g_ik, the zeroth-moment error of disordered particles, and the viscous
//           rates then have growing modes on close pairs (docs/validation.md, "The viscous rates'
//           spectrum").
enum class GradientCorrection { None, Linear, Mixed };

struct PhysicsParams {
  double gm = 1.0;                // G * M of the central point mass
  double nu = 0.0;                // kinematic shear viscosity nu = eta / rho (constant, P98 sec. 3.2)
  double alpha_ss = 0.0;          // > 0: nu = alpha c_s H instead, H = c_s / Omega (shear_viscosity_at)
  double nu_bulk = 0.0;           // kinematic bulk viscosity zeta / rho (P98 eq. 2; zero in the paper)
  double bulk_ratio = 0.0;        // and on top of it bulk_ratio times the shear viscosity (bulk_viscosity_for)
  EquationOfState eos = EquationOfState::None;  // None: pressureless, as in the ring test (P98 5.2)
  double sound_speed = 0.0;       // c_s (isothermal), or c_s0 at R = r0 = 1 (locally isothermal)
  double sound_speed_index = 0.0; // q of c_s(R) = c_s0 R^-q (locally isothermal)
  double gamma = 5.0 / 3.0;       // adiabatic index (adiabatic)
  bool evolve_energy = false;     // integrate du/dt (viscous heating, pressure work)
  // Artificial viscosity (pair_terms.hpp, artificial_viscosity_pair; needs an equation of state):
  // alpha (0: none; with the switch its largest value), beta, and whether the Balsara limiter scales
  // each particle's share; the time-dependent switch of each particle's alpha between av_alpha_min and
  // av_alpha (viscosity_switch.hpp), or one alpha for all.
  double av_alpha = 0.0, av_beta = 2.0;
  bool av_limiter = true;
  bool av_switch = true;
  double av_alpha_min = 0.1;
  double accretion_radius = 0.0;  // particles with r < r_acc are accreted by the central mass
  GradientCorrection gradient_correction = GradientCorrection::Linear;  // discretisation: the kernel gradient (above)
  bool force_correction = false;    // discretisation: moment-corrected, pair-symmetrised kernel gradient in eq. 6 (moment_correction.hpp)
  ViscousForce viscous_force = ViscousForce::Consistent;  // discretisation of eq. 6's divergence (above)
  PairDensity pair_density = PairDensity::Summation;     // the consistent divergence's density ratio (above)
  KernelType kernel = KernelType::Cubic;                   // the summation's kernel (for PairDensity::Others)
  // Whether the particles hold the moment correction C_i = M_i^-1 (core/particles.hpp, correction).
  bool keeps_correction() const { return force_correction || viscous_force == ViscousForce::Consistent; }
  // Whether the particles hold the mixed correction's C~_i e_i (core/particles.hpp, correction_shift):
  // the consistent divergence reads every neighbour's.
  bool keeps_correction_shift() const {
    return viscous_force == ViscousForce::Consistent && gradient_correction == GradientCorrection::Mixed;
  }
  bool artificial_viscosity() const { return av_alpha > 0 && eos != EquationOfState::None; }
  // Whether the particles hold the scatter density (core/particles.hpp, scatter_density): the
  // consistent divergence reads its ln rho (PairDensity::Scatter).
  bool keeps_scatter_density() const {
    return viscous_force == ViscousForce::Consistent && pair_density == PairDensity::Scatter;
  }
  // Whether a pair's kernel value W_ij enters the pair sums (the mixed correction, the others' densities).
  bool needs_kernel_values() const {
    return gradient_correction == GradientCorrection::Mixed ||
           (viscous_force == ViscousForce::Consistent && pair_density == PairDensity::Others);
  }
};

// The configuration's names of the choices above (core/config.cpp lists the allowed ones).
inline constexpr NamedChoice<EquationOfState> kEosNames[] = {{"none", EquationOfState::None},
                                                             {"isothermal", EquationOfState::Isothermal},
                                                             {"locally_isothermal", EquationOfState::LocallyIsothermal},
                                                             {"adiabatic", EquationOfState::Adiabatic}};
inline constexpr NamedChoice<ViscousForce> kViscousForceNames[] = {{"consistent", ViscousForce::Consistent},
                                                                   {"conservative", ViscousForce::Conservative}};
inline constexpr NamedChoice<PairDensity> kPairDensityNames[] = {{"summation", PairDensity::Summation},
                                                                 {"others", PairDensity::Others},
                                                                 {"scatter", PairDensity::Scatter}};
inline constexpr NamedChoice<GradientCorrection> kGradientCorrectionNames[] = {
    {"linear", GradientCorrection::Linear}, {"mixed", GradientCorrection::Mixed}, {"none", GradientCorrection::None}};

inline EquationOfState eos_from_name(std::string_view s) {
  return choice_from_name<EquationOfState>("physics.eos", s, kEosNames);
}
inline ViscousForce viscous_force_from_name(std::string_view s) {
  return choice_from_name<ViscousForce>("sph.viscous_force", s, kViscousForceNames);
}
inline PairDensity pair_density_from_name(std::string_view s) {
  return choice_from_name<PairDensity>("sph.pair_density", s, kPairDensityNames);
}
inline GradientCorrection gradient_correction_from_name(std::string_view s) {
  return choice_from_name<GradientCorrection>("sph.gradient_correction", s, kGradientCorrectionNames);
}

// The sound speed at position x with internal energy u (code units: r0 = 1): c_s, c_s0 R^-q with R
// the cylindrical radius, or (gamma (gamma - 1) u)^(1/2) for the adiabatic equation of state.
template <int D>
double sound_speed_at(const PhysicsParams& p, const Vec<D>& x, double u = 0.0) {
  if (p.eos == EquationOfState::Adiabatic) return std::sqrt(p.gamma * (p.gamma - 1.0) * std::max(u, 0.0));
  if (p.eos != EquationOfState::LocallyIsothermal) return p.sound_speed;
  const double R2 = x[0] * x[0] + x[1] * x[1];
  return p.sound_speed * std::pow(R2, -0.5 * p.sound_speed_index);
}

// Particle i's sound speed (Particles<D>; u is absent without an energy equation).
template <class Particles>
double particle_sound_speed(const Particles& p, std::size_t i, const PhysicsParams& phys) {
  return sound_speed_at(phys, p.pos[i], p.u.empty() ? 0.0 : p.u[i]);
}

// 1 / Omega at position x, Omega = (G M / R^3)^(1/2) at the cylindrical radius R.
template <int D>
double inverse_orbital_frequency(const PhysicsParams& p, const Vec<D>& x) {
  const double R2 = x[0] * x[0] + x[1] * x[1];
  return std::sqrt(R2 * std::sqrt(R2) / p.gm);
}

// The disc's scale height at position x: H = c_s / Omega.
template <int D>
double scale_height_at(const PhysicsParams& p, const Vec<D>& x) {
  return sound_speed_at(p, x) * inverse_orbital_frequency(p, x);
}

// The kinematic shear viscosity at position x: the constant nu, or with alpha_ss > 0 the
// Shakura-Sunyaev nu = alpha c_s H = alpha c_s^2 / Omega (Phantom's irealvisc = 2; docs/physics.md sec. 1).
template <int D>
double shear_viscosity_at(const PhysicsParams& p, const Vec<D>& x) {
  if (!(p.alpha_ss > 0)) return p.nu;
  const double c = sound_speed_at(p, x);
  return p.alpha_ss * c * c * inverse_orbital_frequency(p, x);
}

// The kinematic bulk viscosity where the shear viscosity is nu: a constant, plus a multiple of nu
// (nu_bulk >= 2/3 nu keeps a Keplerian Navier-Stokes disc free of viscous overstability at every
// wavelength; docs/physics.md sec. 4, "Viscous overstability").
inline double bulk_viscosity_for(const PhysicsParams& p, double nu) { return p.nu_bulk + p.bulk_ratio * nu; }

// The larger of the shear and bulk viscosities at x: what the viscous step limits read.
template <int D>
double largest_viscosity_at(const PhysicsParams& p, const Vec<D>& x) {
  const double nu = shear_viscosity_at(p, x);
  return std::max(nu, bulk_viscosity_for(p, nu));
}

// P at density rho, position x and internal energy u (0 without an equation of state).
template <int D>
double pressure(const PhysicsParams& p, double rho, const Vec<D>& x, double u = 0.0) {
  if (p.eos == EquationOfState::None) return 0.0;
  if (p.eos == EquationOfState::Adiabatic) return (p.gamma - 1.0) * rho * u;
  const double c = sound_speed_at(p, x);
  return c * c * rho;
}

}  // namespace sphdisk
