#include "problems/ring_setup.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <stdexcept>
#include <vector>

#include "core/error.hpp"
#include "core/named_choice.hpp"

namespace sphdisk {

Placement placement_from_name(std::string_view name) {
  static constexpr NamedChoice<Placement> kNames[] = {{"random", Placement::Random}, {"stratified", Placement::Stratified}};
  return choice_from_name<Placement>("problem.placement", name, kNames);
}

namespace {

constexpr std::size_t kGrid = 200000;  // radial grid points of the tabulated CDF

// Radial range holding all but a negligible part of the mass: the profile is close to a Gaussian
// of variance tau/2 around r0 (docs/physics.md sec. 4).
void radial_range(const RingSetup& s, double& r_lo, double& r_hi) {
  const double r0 = s.solution.ring_radius;
  const double width = std::sqrt(0.5 * s.tau_start) * r0;
  r_lo = std::max(s.accretion_radius * r0, r0 - 15.0 * width);
  r_lo = std::max(r_lo, 1e-6 * r0);
  r_hi = r0 + 25.0 * width;
}

// Uniform double in [0, 1) from the top 53 bits: the same on every platform.
double uniform01(std::mt19937_64& g) { return static_cast<double>(g() >> 11) * 0x1.0p-53; }

}  // namespace

Particles<2> make_ring(const RingSetup& s) { return make_ring(s, 0, 1); }

Particles<2> make_ring(const RingSetup& s, std::size_t share, std::size_t shares) {
  if (s.particles == 0) throw UserError("problem.particles must be > 0");
  double r_lo, r_hi;
  radial_range(s, r_lo, r_hi);
  // Tabulated CDF of dM/dr = 2 pi r Sigma (trapezoid rule).
  std::vector<double> r(kGrid), cdf(kGrid, 0.0);
  double prev = 0;
  for (std::size_t k = 0; k < kGrid; ++k) {
    r[k] = r_lo + (r_hi - r_lo) * static_cast<double>(k) / static_cast<double>(kGrid - 1);
    const double f = 2.0 * std::numbers::pi * r[k] * s.solution.surface_density(r[k], s.tau_start);
    if (k > 0) cdf[k] = cdf[k - 1] + 0.5 * (f + prev) * (r[k] - r[k - 1]);
    prev = f;
  }
  const double total = cdf.back();
  if (!(total > 0)) throw UserError("ring set-up: the analytic surface density has no mass between the accretion radius and the ring; check problem.tau_start");
  auto inverse_cdf = [&](double q) {
    const double target = q * total;
    const auto it = std::upper_bound(cdf.begin(), cdf.end(), target);
    const std::size_t k = std::clamp<std::size_t>(static_cast<std::size_t>(it - cdf.begin()), 1, kGrid - 1);
    const double t = (target - cdf[k - 1]) / std::max(cdf[k] - cdf[k - 1], 1e-300);
    return r[k - 1] + std::clamp(t, 0.0, 1.0) * (r[k] - r[k - 1]);
  };

  const std::size_t n = s.particles;
  if (shares == 0 || share >= shares) throw std::invalid_argument("make_ring: share out of range");
  Particles<2> p;
  p.resize(n > share ? (n - share + shares - 1) / shares : 0);
  std::mt19937_64 gen(s.seed);
  const double m = s.solution.disc_mass / static_cast<double>(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (i % shares != share) {  // another share's particle: draw its two numbers, keep nothing
      gen.discard(2);
      continue;
    }
    const std::size_t k = i / shares;
    const double u = uniform01(gen);
    const double q = s.stratified ? (static_cast<double>(i) + u) / static_cast<double>(n) : u;
    const double ri = inverse_cdf(q);
    // Uniform azimuth in both modes. (Not a golden-angle Vogel spiral: Keplerian shear turns it into
    // dense radial bands within a few orbits, far worse than random azimuths.)
    const double phi = 2.0 * std::numbers::pi * uniform01(gen);
    const double c = std::cos(phi), sn = std::sin(phi);
    const double v_phi = 1.0 / std::sqrt(ri);  // Kepler, G M = 1
    const double v_r = s.solution.radial_velocity(ri, s.tau_start);
    p.id[k] = i + 1;  // GADGET convention: IDs start at 1
    p.mass[k] = m;
    p.pos[k] = Vec<2>{{ri * c, ri * sn}};
    p.vel[k] = Vec<2>{{v_r * c - v_phi * sn, v_r * sn + v_phi * c}};
  }
  return p;
}

double ring_smoothing_length(const RingSetup& s, double neighbours) {
  double r_lo, r_hi;
  radial_range(s, r_lo, r_hi);
  const double m = s.solution.disc_mass;
  double integral = 0, prev = 0;
  const std::size_t k_max = 20000;
  for (std::size_t k = 0; k < k_max; ++k) {
    const double r = r_lo + (r_hi - r_lo) * static_cast<double>(k) / static_cast<double>(k_max - 1);
    const double sig = s.solution.surface_density(r, s.tau_start) / m;
    const double f = sig * sig * 2.0 * std::numbers::pi * r;
    if (k > 0) integral += 0.5 * (f + prev) * (r_hi - r_lo) / static_cast<double>(k_max - 1);
    prev = f;
  }
  return std::sqrt(neighbours / (4.0 * std::numbers::pi * static_cast<double>(s.particles) * integral));
}

}  // namespace sphdisk
