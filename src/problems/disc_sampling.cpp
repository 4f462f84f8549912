#include "problems/disc_sampling.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/portable_random.hpp"

namespace sphdisk {

namespace {

constexpr std::size_t kGrid = 200000;  // radial grid points of the tabulated CDF

double sound_speed_at_radius(const DiscSampling& s, double R) { return s.placement.sound_speed * std::pow(R, -s.placement.sound_speed_index); }

// The azimuthal speed that holds a particle at cylindrical radius R and height z on a circle:
// v_phi^2 = G M R^2 / (R^2 + z^2)^(3/2) + (R / rho) dP/dR, with P = c_s(R)^2 rho and rho the
// profile's density (Sigma in 2D; Sigma / (sqrt(2 pi) H) exp(-z^2 / 2 H^2) in 3D). The pressure
// term, c_s^2 d ln(c_s^2 rho) / d ln R, from a central difference; dropped where the profile has
// underflowed or ends (far out in a ring's wings; at a disc's edges).
template <int D>
double circular_speed(const DiscSampling& s, double R, double z) {
  if (!(s.placement.sound_speed > 0)) return 1.0 / std::sqrt(R);  // Kepler (pressureless discs are 2D: z = 0)
  const double gravity = R * R / std::pow(R * R + z * z, 1.5);
  auto ln_pressure = [&](double r) {
    const double c = sound_speed_at_radius(s, r);
    double ln_rho = std::log(s.surface_density(r));
    if constexpr (D == 3) {
      const double H = scale_height(s, r);
      ln_rho -= std::log(H) + 0.5 * z * z / (H * H);
    }
    return std::log(c * c) + ln_rho;
  };
  const double dr = 1e-5 * R;
  const double slope = (ln_pressure(R + dr) - ln_pressure(R - dr)) / (2 * dr) * R;
  const double c = sound_speed_at_radius(s, R);
  const double pressure = std::isfinite(slope) ? c * c * slope : 0.0;
  return std::sqrt(std::max(gravity + pressure, 0.0));
}

}  // namespace

double scale_height(const DiscSampling& s, double R) { return sound_speed_at_radius(s, R) * std::pow(R, 1.5); }

template <int D>
Particles<D> sample_disc(const DiscSampling& s, std::size_t share, std::size_t shares) {
  static_assert(D == 2 || D == 3);
  if (D == 3 && !(s.placement.sound_speed > 0))
    throw UserError(std::string(s.what) + " set-up: a 3D disc needs a sound speed for its vertical equilibrium (physics.aspect_ratio)");
  if (s.placement.particles == 0) throw UserError("problem.particles must be > 0");
  if (shares == 0 || share >= shares) throw std::invalid_argument("sample_disc: share out of range");
  // Tabulated CDF of dM/dR = 2 pi R Sigma (trapezoid rule).
  std::vector<double> r(kGrid), cdf(kGrid, 0.0);
  double prev = 0;
  for (std::size_t k = 0; k < kGrid; ++k) {
    r[k] = s.r_lo + (s.r_hi - s.r_lo) * static_cast<double>(k) / static_cast<double>(kGrid - 1);
    const double f = 2.0 * std::numbers::pi * r[k] * s.surface_density(r[k]);
    if (k > 0) cdf[k] = cdf[k - 1] + 0.5 * (f + prev) * (r[k] - r[k - 1]);
    prev = f;
  }
  const double total = cdf.back();
  if (!(total > 0))
    throw UserError(std::string(s.what) + " set-up: the surface density has no mass between " + std::to_string(s.r_lo) +
                    " and " + std::to_string(s.r_hi) + " r0; check the set-up's radii and problem.tau_start");
  auto inverse_cdf = [&](double q) {
    const double target = q * total;
    const auto it = std::upper_bound(cdf.begin(), cdf.end(), target);
    const std::size_t k = std::clamp<std::size_t>(static_cast<std::size_t>(it - cdf.begin()), 1, kGrid - 1);
    const double t = (target - cdf[k - 1]) / std::max(cdf[k] - cdf[k - 1], 1e-300);
    return r[k - 1] + std::clamp(t, 0.0, 1.0) * (r[k] - r[k - 1]);
  };

  const std::size_t n = s.placement.particles;
  Particles<D> p;
  p.resize(n > share ? (n - share + shares - 1) / shares : 0);
  constexpr int draws = D == 2 ? 2 : 4;  // radius, azimuth (and two for the height)
  std::mt19937_64 gen(s.placement.seed);
  const double m = s.mass / static_cast<double>(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (i % shares != share) {  // another share's particle: draw its numbers, keep nothing
      gen.discard(draws);
      continue;
    }
    const std::size_t k = i / shares;
    const double u = uniform01(gen);
    const double q = s.placement.stratified ? (static_cast<double>(i) + u) / static_cast<double>(n) : u;
    const double ri = inverse_cdf(q);
    // Uniform azimuth in both modes. (Not a golden-angle Vogel spiral: Keplerian shear turns it into
    // dense radial bands within a few orbits, far worse than random azimuths.)
    const double phi = 2.0 * std::numbers::pi * uniform01(gen);
    const double c = std::cos(phi), sn = std::sin(phi);
    double z = 0;
    if constexpr (D == 3) {
      const double u1 = uniform01(gen);
      z = scale_height(s, ri) * standard_normal(u1, uniform01(gen));
    }
    const double v_phi = circular_speed<D>(s, ri, z);
    const double v_r = s.radial_velocity ? s.radial_velocity(ri) : 0.0;
    p.id[k] = i + 1;  // GADGET convention: IDs start at 1
    p.mass[k] = m;
    p.pos[k][0] = ri * c, p.pos[k][1] = ri * sn;
    p.vel[k][0] = v_r * c - v_phi * sn, p.vel[k][1] = v_r * sn + v_phi * c;
    if constexpr (D == 3) p.pos[k][2] = z, p.vel[k][2] = 0;
  }
  return p;
}

template Particles<2> sample_disc(const DiscSampling&, std::size_t, std::size_t);
template Particles<3> sample_disc(const DiscSampling&, std::size_t, std::size_t);

}  // namespace sphdisk
