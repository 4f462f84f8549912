// The ring's initial conditions (problems/ring_setup.hpp): in 2D and 3D, with and without pressure.
#include <gtest/gtest.h>

#include <cmath>

#include "problems/ring_setup.hpp"

using namespace sphdisk;

namespace {

RingSetup ring_with_pressure(double aspect_ratio, double q) {
  RingSetup s;
  s.solution = RingSolution{1e-10, 1.0, 4.8e-5};
  s.placement.particles = 20000;
  s.placement.sound_speed = aspect_ratio;
  s.placement.sound_speed_index = q;
  return s;
}

double cylindrical_radius(const Vec<3>& x) { return std::hypot(x[0], x[1]); }

}  // namespace

TEST(RingSetup, HeightsFollowTheScaleHeightOfVerticalEquilibrium) {
  const RingSetup s = ring_with_pressure(0.05, 0.25);
  const Particles<3> p = make_ring<3>(s);
  ASSERT_EQ(p.size(), s.placement.particles);
  double mean = 0, mean_square = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double u = p.pos[i][2] / ring_scale_height(s, cylindrical_radius(p.pos[i]));
    mean += u, mean_square += u * u;
  }
  mean /= static_cast<double>(p.size()), mean_square /= static_cast<double>(p.size());
  // z / H(R) is a standard normal number: mean 0 and variance 1 within a few standard errors.
  EXPECT_NEAR(mean, 0.0, 4.0 / std::sqrt(static_cast<double>(p.size())));
  EXPECT_NEAR(mean_square, 1.0, 4.0 * std::sqrt(2.0 / static_cast<double>(p.size())));
  EXPECT_NEAR(ring_scale_height(s, 1.0), 0.05, 1e-15);  // H/R = aspect ratio at r0
  EXPECT_NEAR(ring_scale_height(s, 2.0) / 2.0, 0.05 * std::pow(2.0, 0.5 - 0.25), 1e-15);  // H/R ~ R^(1/2 - q)
}

TEST(RingSetup, PressureTurnsTheRotationFasterInsideAndSlowerOutside) {
  // The pressure grows towards the ring's core from both sides: inside it pushes inwards (faster
  // than Kepler), outside outwards (slower); in 3D the height lowers gravity's pull a little more.
  const RingSetup s = ring_with_pressure(0.05, 0.25);
  const Particles<3> p = make_ring<3>(s);
  int inside = 0, outside = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double R = cylindrical_radius(p.pos[i]);
    const double v_phi = (p.pos[i][0] * p.vel[i][1] - p.pos[i][1] * p.vel[i][0]) / R;
    const double kepler = 1.0 / std::sqrt(R);
    if (R < 0.9) inside += v_phi > kepler ? 1 : -1;
    if (R > 1.1) outside += v_phi < kepler ? 1 : -1;
    EXPECT_EQ(p.vel[i][2], 0.0);
  }
  EXPECT_GT(inside, 0);
  EXPECT_GT(outside, 0);
}

TEST(RingSetup, WithoutPressureTheRingIsKeplerianIn2D) {
  RingSetup s;
  s.solution = RingSolution{1e-10, 1.0, 4.8e-5};
  s.placement.particles = 1000;
  const Particles<2> p = make_ring<2>(s);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double R = std::sqrt(norm2(p.pos[i]));
    const double v_phi = (p.pos[i][0] * p.vel[i][1] - p.pos[i][1] * p.vel[i][0]) / R;
    EXPECT_NEAR(v_phi, 1.0 / std::sqrt(R), 1e-12);
  }
  EXPECT_THROW(make_ring<3>(s), std::exception);  // a 3D ring needs pressure to stand up
}

TEST(RingSetup, SharesTogetherAreTheWholeSetIn3D) {
  const RingSetup s = ring_with_pressure(0.05, 0.25);
  const Particles<3> all = make_ring<3>(s);
  for (std::size_t share = 0; share < 3; ++share) {
    const Particles<3> part = make_ring<3>(s, share, 3);
    for (std::size_t k = 0; k < part.size(); ++k) {
      const std::size_t i = share + 3 * k;
      ASSERT_EQ(part.id[k], all.id[i]);
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(part.pos[k][c], all.pos[i][c]);
        EXPECT_EQ(part.vel[k][c], all.vel[i][c]);
      }
    }
  }
}
