#pragma once
// Explicit timestep criteria (physics.md sec. 3, Phantom's defaults):
//   orbital  C_orb / Omega_i, Omega_i = sqrt(G M / r_i^3)   (dominates for the ring)
//   force    C_force sqrt(h_i / |a_i|)
//   viscous  C_visc h_i^2 / max(nu, nu_bulk)
//   Courant  C_cour h_i / c_s                                (only with an equation of state)
// The smallest over particles is returned; min is exact, so it does not depend on thread count.
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
};

// Limits that keep an explicit scheme stable whatever its error control says.
inline double stability_timestep(double h, const PhysicsParams& phys, const TimestepFactors& f) {
  double dt = std::numeric_limits<double>::infinity();
  const double nu = std::max(phys.nu, phys.nu_bulk);
  if (nu > 0) dt = std::min(dt, f.viscous * h * h / nu);
  if (phys.eos != EquationOfState::None && phys.sound_speed > 0) dt = std::min(dt, f.courant * h / phys.sound_speed);
  return dt;
}

template <int D>
double particle_timestep(const Particles<D>& p, std::size_t i, const PhysicsParams& phys, const TimestepFactors& f) {
  const double r = norm(p.pos[i]);
  double dt = f.orbital * std::sqrt(r * r * r / phys.gm);
  const double a = norm(p.acc[i]);
  if (a > 0) dt = std::min(dt, f.force * std::sqrt(p.h[i] / a));
  return std::min(dt, stability_timestep(p.h[i], phys, f));
}

template <int D>
double explicit_timestep(const Particles<D>& p, const PhysicsParams& phys, const TimestepFactors& f) {
  const double inf = std::numeric_limits<double>::infinity();
  return par::reduce(
      p.size(), inf, [&](std::size_t i) { return particle_timestep(p, i, phys, f); },
      [](double a, double b) { return std::min(a, b); });
}

template <int D>
double smallest_smoothing_length(const Particles<D>& p) {
  return par::reduce(
      p.size(), std::numeric_limits<double>::infinity(), [&](std::size_t i) { return p.h[i]; },
      [](double a, double b) { return std::min(a, b); });
}

}  // namespace sphdisk
