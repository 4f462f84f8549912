#pragma once
// Initial conditions of the viscously spreading ring (P98 sec. 5.2; docs/physics.md sec. 4): particles
// "placed stochastically on Kepler orbits" following the analytic surface density at tau_start.
// Radii come from the inverse CDF of 2 pi r Sigma(r, tau_start) on a fine grid, azimuths are
// uniform, velocities are Keplerian plus the analytic radial velocity. With pressure the rotation
// is what balances gravity and the radial pressure gradient; in 3D the heights are Gaussian with
// the scale height H = c_s / Omega of vertical hydrostatic equilibrium. A seeded generator makes
// the same particles for the same seed, on any machine (no std:: distributions, whose algorithms
// are implementation-defined).
#include <cstdint>
#include <string_view>

#include "core/particles.hpp"
#include "problems/disc_sampling.hpp"
#include "problems/ring_analytic.hpp"

namespace sphdisk {

// How the radii are drawn (problem.placement): independently from the profile ("random", P98 5.2),
// or one in each of N equal-mass quantiles ("stratified": a low-noise variant).
enum class Placement { Random, Stratified };
Placement placement_from_name(std::string_view name);

struct RingSetup {
  RingSolution solution;       // code units: r0 = 1, G M = 1
  double tau_start = 0.018;
  ParticlePlacement placement;
  double accretion_radius = 0.05;
};

// The particle set at tau_start in D = 2 or 3 dimensions (smoothing lengths left at zero).
template <int D = 2>
Particles<D> make_ring(const RingSetup& s);
// Share `share` of `shares` of the same set: particles share, share + shares, ... (memory O(N/shares);
// each process of a distributed run makes its own).
template <int D = 2>
Particles<D> make_ring(const RingSetup& s, std::size_t share, std::size_t shares);

// The scale height H = c_s / Omega at cylindrical radius R (G M = r0 = 1).
double ring_scale_height(const RingSetup& s, double R);

// 2D: the smoothing length giving `neighbours` mean neighbours (excluding self) at tau_start:
//   <N_nb> = N pi (2h)^2 integral (Sigma/m)^2 2 pi r dr,
// so h is proportional to N^(-1/2), as the paper scales it (P98 sec. 5.3).
double ring_smoothing_length(const RingSetup& s, double neighbours);

}  // namespace sphdisk
