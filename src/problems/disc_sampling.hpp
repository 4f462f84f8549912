#pragma once
// Particles drawn from an axisymmetric disc (the ring's and the power-law disc's set-ups): radii
// from the inverse CDF of 2 pi R Sigma(R) tabulated on a fine grid, uniform azimuths, in 3D heights
// from the Gaussian of vertical hydrostatic equilibrium with scale height H = c_s / Omega, and the
// rotation that balances the point mass's gravity and the pressure gradient (Kepler where
// pressureless), plus a given radial velocity. A seeded generator makes the same particles for the
// same seed on any machine (no std:: distributions, whose algorithms are implementation-defined),
// and on any number of shares (one per process of a distributed run).
#include <cstddef>
#include <cstdint>
#include <functional>

#include "core/particles.hpp"

namespace sphdisk {

// How the particles of any disc set-up (the ring, the power-law disc) are placed: their number,
// the seed, the radii's sampling, and the sound speed that sets heights and rotation.
struct ParticlePlacement {
  std::size_t particles = 10000;
  std::uint64_t seed = 42;
  bool stratified = false;     // Placement::Stratified (ring_setup.hpp): radii at (k + U)/N quantiles instead of U
  // Pressure (code units): c_s(R) = sound_speed R^-sound_speed_index; 0: pressureless (2D only).
  double sound_speed = 0;
  double sound_speed_index = 0;
};

struct DiscSampling {
  std::function<double(double)> surface_density;  // Sigma(R), any normalisation (code units: G M = 1)
  std::function<double(double)> radial_velocity;  // v_R(R); empty: 0
  double r_lo = 0, r_hi = 0;   // radial range drawn from
  double mass = 0;             // total mass of the particles
  ParticlePlacement placement;
  const char* what = "disc";   // the set-up, for error messages
};

// The scale height H = c_s / Omega at cylindrical radius R.
double scale_height(const DiscSampling& s, double R);

// Share `share` of `shares` of the particle set: particles share, share + shares, ... (IDs from 1).
template <int D>
Particles<D> sample_disc(const DiscSampling& s, std::size_t share = 0, std::size_t shares = 1);

}  // namespace sphdisk
