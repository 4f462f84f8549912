#pragma once
// The artificial viscosity's time-dependent switch (Morris & Monaghan 1997): each particle's alpha
// follows
//   d alpha / dt = -(alpha - alpha_min) / tau + max(-div v, 0) (alpha_max - alpha),
// tau = h / (sigma c), sigma = 0.1 (the decay constant Phantom uses), so that alpha rises to
// alpha_max within a few steps where the flow converges (a shock) and decays over ~10 sound-crossing
// times of a kernel behind it. Over a step of length dt, with the source from the particle's last
// rate evaluation held fixed, the equation is linear in alpha with constant coefficients and is
// integrated exactly: alpha -> alpha_eq + (alpha - alpha_eq) exp(-k dt), k = 1 / tau + S,
// alpha_eq = (alpha_min / tau + S alpha_max) / k, which stays within [alpha_min, alpha_max] for any
// step. The integrators apply it where each particle's step ends (integrate/), after the closing kick.
#include <cmath>
#include <cstddef>

#include "physics/physics_params.hpp"

namespace sphdisk {

inline constexpr double kViscositySwitchDecay = 0.1;  // sigma of tau = h / (sigma c)

// alpha after a step dt from alpha, with the compression S = max(-div v, 0), smoothing length h and
// sound speed c.
inline double switched_alpha(double alpha, double S, double h, double c, double dt, const PhysicsParams& phys) {
  const double decay = kViscositySwitchDecay * c / h, k = decay + S;
  if (!(k > 0)) return alpha;  // no sound speed and no compression: nothing changes it
  const double equilibrium = (phys.av_alpha_min * decay + S * phys.av_alpha) / k;
  return equilibrium + (alpha - equilibrium) * std::exp(-k * dt);
}

// Particle i's alpha after its step of length dt (Particles<D>; its compression from the rate
// evaluation at the step's end).
template <class Particles>
void advance_viscosity_switch(Particles& p, std::size_t i, double dt, const PhysicsParams& phys) {
  p.av_alpha[i] = switched_alpha(p.av_alpha[i], p.compression[i], p.h[i], particle_sound_speed(p, i, phys), dt, phys);
}

}  // namespace sphdisk
