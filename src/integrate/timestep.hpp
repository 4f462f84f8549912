#pragma once
// Explicit timestep criteria (docs/physics.md sec. 3, Phantom's defaults):
//   orbital  C_orb / Omega_i, Omega_i = sqrt(G M / r_i^3)   (dominates for the ring)
//   force    C_force sqrt(h_i / |a_i|)
//   viscous  C_visc h_i^2 / max(nu, nu_bulk)
//   Courant  C_cour h_i / c_s                                (only with an equation of state)
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/particles.hpp"
#include "parallel/loops.hpp"
#include "physics/physics_params.hpp"

namespace sphdisk {

struct TimestepFactors {
  double orbital = 0.25;
  double force = 0.25;
  double viscous = 0.1;
  double courant = 0.3;
  // respa only: the point mass's gravity is substepped with steps <= substep / Omega_i
  // (leapfrog.cpp). Finer than `orbital`: each particle's substep count jumps with radius, and the
  // KDK velocity error O((Omega dt)^2) jumps with it, which the viscous stress reads as shear.
  double substep = 0.05;
};

// (infinite without a point mass: gm = 0)
inline double orbital_timestep(double r, double gm, double factor) { return factor * std::sqrt(r * r * r / gm); }

inline double force_timestep(double h, double a, double factor) {
  return a > 0 ? factor * std::sqrt(h / a) : std::numeric_limits<double>::infinity();
}

// Limits that keep an explicit scheme stable whatever its error control says; nu: the larger of the
// shear and bulk viscosities, c_s: the sound speed (where the equation of state has one).
inline double stability_timestep(double h, double nu, double c_s, const PhysicsParams& phys, const TimestepFactors& f) {
  double dt = std::numeric_limits<double>::infinity();
  if (nu > 0) dt = std::min(dt, f.viscous * h * h / nu);
  if (phys.eos != EquationOfState::None && c_s > 0) dt = std::min(dt, f.courant * h / c_s);
  return dt;
}

// With gravity substepped (respa, block) acc holds the hydrodynamic acceleration only, so the same
// criteria give the SPH forces' own step: the force criterion sees the SPH forces alone (Phantom's
// dtforce) and the orbital limit keeps them sampled several times per orbit.
template <int D>
double particle_timestep(const Particles<D>& p, std::size_t i, const PhysicsParams& phys, const TimestepFactors& f) {
  double dt = std::min(orbital_timestep(norm(p.pos[i]), phys.gm, f.orbital), force_timestep(p.h[i], norm(p.acc[i]), f.force));
  // With artificial viscosity the Courant limit takes the largest signal speed of the particle's
  // pairs, sound speed plus beta times an approach speed (Phantom's dtcourant).
  if (!p.signal_speed.empty() && p.signal_speed[i] > 0) dt = std::min(dt, f.courant * p.h[i] / p.signal_speed[i]);
  return std::min(dt, stability_timestep(p.h[i], largest_viscosity_at(phys, p.pos[i]), particle_sound_speed(p, i, phys), phys, f));
}

// Smallest dt_of(i) over the particles; min is exact, so it does not depend on thread count.
template <class DtOf>
double smallest_timestep(std::size_t n, DtOf dt_of) {
  return par::reduce(n, std::numeric_limits<double>::infinity(), dt_of, [](double a, double b) { return std::min(a, b); });
}

template <int D>
double explicit_timestep(const Particles<D>& p, const PhysicsParams& phys, const TimestepFactors& f) {
  return smallest_timestep(p.size(), [&](std::size_t i) { return particle_timestep(p, i, phys, f); });
}

// The largest sound speed and the largest viscosity (shear or bulk) over the particles (the
// locally isothermal c_s is largest at small R, an alpha viscosity at large R).
template <int D>
double largest_sound_speed(const Particles<D>& p, const PhysicsParams& phys) {
  return par::reduce(
      p.size(), 0.0, [&](std::size_t i) { return particle_sound_speed(p, i, phys); },
      [](double a, double b) { return std::max(a, b); });
}
template <int D>
double largest_viscosity(const Particles<D>& p, const PhysicsParams& phys) {
  return par::reduce(
      p.size(), 0.0, [&](std::size_t i) { return largest_viscosity_at(phys, p.pos[i]); },
      [](double a, double b) { return std::max(a, b); });
}

template <int D>
double smallest_smoothing_length(const Particles<D>& p) {
  return par::reduce(
      p.size(), std::numeric_limits<double>::infinity(), [&](std::size_t i) { return p.h[i]; },
      [](double a, double b) { return std::min(a, b); });
}

}  // namespace sphdisk
