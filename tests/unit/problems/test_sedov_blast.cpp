// The Sedov-Taylor blast wave's initial conditions (problems/sedov_blast.hpp).
#include <gtest/gtest.h>

#include <set>

#include "core/error.hpp"
#include "problems/sedov_blast.hpp"

using namespace sphdisk;

TEST(SedovBlast, LatticeHoldsUnitMassAndTheBlastEnergy) {
  SedovBlast s;
  s.particles = 30000;  // 31^3 = 29,791 in 3D, 173^2 in 2D
  s.energy = 2.5;
  s.gamma = 1.4;
  const auto p = make_sedov_blast<3>(s);
  ASSERT_EQ(p.size(), 31u * 31u * 31u);
  double mass = 0, energy = 0;
  std::size_t hot = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    mass += p.mass[i];
    energy += p.mass[i] * p.u[i];
    hot += norm(p.pos[i]) < sedov_blast_radius<3>(s);
    for (int d = 0; d < 3; ++d) EXPECT_LT(std::abs(p.pos[i][d]), 0.5);
    EXPECT_EQ(norm(p.vel[i]), 0.0);
  }
  EXPECT_NEAR(mass, 1.0, 1e-12);
  EXPECT_NEAR(energy, s.energy * (1 + SedovBlast::kAmbientPressure / (s.gamma - 1)), 1e-10);  // (round-off of the sum)
  EXPECT_GT(hot, 40u);  // about central_particles = 60 (a lattice's count inside a sphere)
  EXPECT_LT(hot, 80u);
  EXPECT_EQ(make_sedov_blast<2>(s).size(), 173u * 173u);
}

TEST(SedovBlast, SharesPartitionTheParticles) {
  SedovBlast s;
  s.particles = 4096;
  const auto all = make_sedov_blast<3>(s);
  std::set<std::uint64_t> ids;
  for (std::size_t k = 0; k < 3; ++k) {
    const auto part = make_sedov_blast<3>(s, k, 3);
    for (std::size_t i = 0; i < part.size(); ++i) {
      EXPECT_TRUE(ids.insert(part.id[i]).second);
      const std::size_t at = part.id[i] - 1;  // ids are lattice indices + 1
      EXPECT_EQ(part.pos[i][0], all.pos[at][0]);
      EXPECT_EQ(part.u[i], all.u[at]);
    }
  }
  EXPECT_EQ(ids.size(), all.size());
}

TEST(SedovBlast, TooFewParticlesAreRefused) {
  SedovBlast s;
  s.particles = 300;  // 7 per side in 3D
  EXPECT_THROW(make_sedov_blast<3>(s), UserError);
}
