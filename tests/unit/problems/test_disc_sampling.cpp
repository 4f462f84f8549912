// The power-law disc (problems/power_law_disc.hpp) drawn by the disc sampler (disc_sampling.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "problems/disc_sampling.hpp"
#include "problems/power_law_disc.hpp"

using namespace sphdisk;

namespace {

DiscSampling phantom_like_disc(std::size_t particles) {
  DiscSampling s = power_law_sampling({1.0, 5.0, 1.0, 1e-3});
  s.placement.particles = particles;
  s.placement.sound_speed = 0.05;  // H/R = 0.05 at R = 1
  s.placement.sound_speed_index = 0.25;
  return s;
}

}  // namespace

TEST(PowerLawDisc, SurfaceDensityHoldsTheDiscMass) {
  for (double p : {0.0, 1.0, 1.5, 2.0}) {
    const PowerLawDisc d{1.0, 5.0, p, 1e-3};
    double mass = 0;
    const int n = 200000;
    for (int k = 0; k < n; ++k) {  // midpoint rule over [R_in, R_out]
      const double R = 1.0 + 4.0 * (k + 0.5) / n;
      mass += 2.0 * std::numbers::pi * R * power_law_surface_density(d, R) * 4.0 / n;
    }
    EXPECT_NEAR(mass / 1e-3, 1.0, 1e-8) << "p = " << p;
    EXPECT_EQ(power_law_surface_density(d, 0.99), 0.0);
    EXPECT_EQ(power_law_surface_density(d, 5.01), 0.0);
    EXPECT_NEAR(power_law_surface_density(d, 2.0) / power_law_surface_density(d, 4.0), std::pow(2.0, p), 1e-12);
  }
}

TEST(PowerLawDisc, RadiiFollowTheEnclosedMass) {
  // Sigma ~ 1/R: the mass inside R grows as R - R_in, so a quarter of it lies inside R = 2.
  const Particles<3> p = sample_disc<3>(phantom_like_disc(40000));
  std::size_t inside = 0;
  for (std::size_t i = 0; i < p.size(); ++i) inside += std::hypot(p.pos[i][0], p.pos[i][1]) < 2.0;
  const double n = static_cast<double>(p.size()), expected = 0.25;
  EXPECT_NEAR(static_cast<double>(inside) / n, expected, 4.0 * std::sqrt(expected * (1 - expected) / n));
}

TEST(PowerLawDisc, RotationBalancesGravityAndThePressureGradient) {
  // Locally isothermal, c_s = c_0 R^-q, rho = Sigma / (sqrt(2 pi) H) exp(-z^2 / 2 H^2), H = c_s / Omega:
  //   v_phi^2 = R^2 / (R^2 + z^2)^(3/2) + c_s^2 [-(p + q + 3/2) + (3/2 - q) z^2 / H^2].
  const DiscSampling s = phantom_like_disc(5000);
  const Particles<3> p = sample_disc<3>(s);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double R = std::hypot(p.pos[i][0], p.pos[i][1]), z = p.pos[i][2];
    const double c = 0.05 * std::pow(R, -0.25), H = scale_height(s, R);
    if (R < 1.001 || R > 4.999) continue;  // the derivative's stencil crosses an edge
    const double want = R * R / std::pow(R * R + z * z, 1.5) + c * c * (-(1.0 + 0.25 + 1.5) + (1.5 - 0.25) * z * z / (H * H));
    const double v_phi = (p.pos[i][0] * p.vel[i][1] - p.pos[i][1] * p.vel[i][0]) / R;
    ASSERT_NEAR(v_phi * v_phi / want, 1.0, 1e-7) << "R = " << R << ", z = " << z;
    EXPECT_NEAR(std::hypot(p.vel[i][0], p.vel[i][1]), std::abs(v_phi), 1e-12);  // no radial velocity
  }
  EXPECT_NEAR(scale_height(s, 1.0), 0.05, 1e-15);
}
