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

double ring_scale_height(const RingSetup& s, double R) {
  return s.sound_speed * std::pow(R, -s.sound_speed_index) * std::pow(R, 1.5);
}

namespace {

// The azimuthal speed that holds a particle at cylindrical radius R and height z on a circle:
// v_phi^2 = G M R^2 / (R^2 + z^2)^(3/2) + (R / rho) dP/dR, with P = c_s(R)^2 rho and rho the
// profile's density (Sigma in 2D; Sigma / (sqrt(2 pi) H) exp(-z^2 / 2 H^2) in 3D). The pressure
// term, c_s^2 d ln(c_s^2 rho) / d ln R, from a central difference; dropped where the profile has
// underflowed (far out in the wings, where no particle is drawn in practice).
template <int D>
double circular_speed(const RingSetup& s, double R, double z) {
  if (!(s.sound_speed > 0)) return 1.0 / std::sqrt(R);  // Kepler (pressureless rings are 2D: z = 0)
  const double gravity = R * R / std::pow(R * R + z * z, 1.5);
  auto ln_pressure = [&](double r) {
    const double c = s.sound_speed * std::pow(r, -s.sound_speed_index);
    double ln_rho = std::log(s.solution.surface_density(r, s.tau_start));
    if constexpr (D == 3) {
      const double H = ring_scale_height(s, r);
      ln_rho -= std::log(H) + 0.5 * z * z / (H * H);
    }
    return std::log(c * c) + ln_rho;
  };
  const double dr = 1e-5 * R;
  const double slope = (ln_pressure(R + dr) - ln_pressure(R - dr)) / (2 * dr) * R;
  const double c = s.sound_speed * std::pow(R, -s.sound_speed_index);
  const double pressure = std::isfinite(slope) ? c * c * slope : 0.0;
  return std::sqrt(std::max(gravity + pressure, 0.0));
}

// A standard normal number from two uniforms (Box-Muller, cosine branch).
double standard_normal(double u1, double u2) {
  return std::sqrt(-2.0 * std::log(1.0 - u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

}  // namespace

template <int D>
Particles<D> make_ring(const RingSetup& s) { return make_ring<D>(s, 0, 1); }

template <int D>
Particles<D> make_ring(const RingSetup& s, std::size_t share, std::size_t shares) {
  static_assert(D == 2 || D == 3);
  if (D == 3 && !(s.sound_speed > 0))
    throw UserError("ring set-up: a 3D ring needs a sound speed for its vertical equilibrium (physics.aspect_ratio)");
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
  Particles<D> p;
  p.resize(n > share ? (n - share + shares - 1) / shares : 0);
  constexpr int draws = D == 2 ? 2 : 4;  // radius, azimuth (and two for the height)
  std::mt19937_64 gen(s.seed);
  const double m = s.solution.disc_mass / static_cast<double>(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (i % shares != share) {  // another share's particle: draw its numbers, keep nothing
      gen.discard(draws);
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
    double z = 0;
    if constexpr (D == 3) {
      const double u1 = uniform01(gen);
      z = ring_scale_height(s, ri) * standard_normal(u1, uniform01(gen));
    }
    const double v_phi = circular_speed<D>(s, ri, z);  // Kepler (G M = 1) where pressureless
    const double v_r = s.solution.radial_velocity(ri, s.tau_start);
    p.id[k] = i + 1;  // GADGET convention: IDs start at 1
    p.mass[k] = m;
    p.pos[k][0] = ri * c, p.pos[k][1] = ri * sn;
    p.vel[k][0] = v_r * c - v_phi * sn, p.vel[k][1] = v_r * sn + v_phi * c;
    if constexpr (D == 3) p.pos[k][2] = z, p.vel[k][2] = 0;
  }
  return p;
}

template Particles<2> make_ring(const RingSetup&);
template Particles<3> make_ring(const RingSetup&);
template Particles<2> make_ring(const RingSetup&, std::size_t, std::size_t);
template Particles<3> make_ring(const RingSetup&, std::size_t, std::size_t);

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
