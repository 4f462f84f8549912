// The radial profiles of `sphdisk analyze` for discs (app/disc_profiles.hpp): by hand on two rings of
// particles on circular orbits, one with heights (a 3D disc seen from above, app/disc_plane.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "app/disc_plane.hpp"
#include "app/disc_profiles.hpp"

using namespace sphdisk;

TEST(DiscProfiles, BinsMassMotionAndHeightsByHand) {
  // 100 particles of mass 0.01 on each of the circles R = 1.75 and 2.75 (Kepler, G M = 1), at heights
  // +-H with H = 0.1 R: a layer whose rms height is H.
  Particles<3> p3;
  p3.resize(200);
  for (std::size_t i = 0; i < p3.size(); ++i) {
    const double R = i < 100 ? 1.75 : 2.75, phi = 2.0 * std::numbers::pi * static_cast<double>(i % 100) / 100.0;
    p3.id[i] = i + 1;
    p3.mass[i] = 0.01;
    p3.h[i] = 0.1;
    p3.rho[i] = 1.0;
    p3.pos[i] = Vec<3>{{R * std::cos(phi), R * std::sin(phi), (i % 2 ? 0.1 : -0.1) * R}};
    p3.vel[i] = Vec<3>{{-std::sin(phi) / std::sqrt(R), std::cos(phi) / std::sqrt(R), 0.0}};
  }
  std::vector<double> z;
  for (const auto& x : p3.pos) z.push_back(x[2]);
  SnapshotMeta meta;
  meta.dimension = 3;
  const DiscProfiles d = disc_profiles(seen_from_above(p3), meta, 4, 1.0, 3.0, &z);
  ASSERT_EQ(d.bins.size(), 4u);
  ASSERT_TRUE(d.heights);
  EXPECT_NEAR(d.mass, 2.0, 1e-12);
  for (std::size_t b : {std::size_t{1}, std::size_t{3}}) {  // [1.5, 2) holds R = 1.75, [2.5, 3) R = 2.75
    const DiscBin& bin = d.bins[b];
    const double R = b == 1 ? 1.75 : 2.75;
    EXPECT_EQ(bin.count, 100u);
    EXPECT_NEAR(bin.sigma, 1.0 / (std::numbers::pi * (bin.r_hi * bin.r_hi - bin.r_lo * bin.r_lo)), 1e-12);
    EXPECT_NEAR(bin.z_rms, 0.1 * R, 1e-12);
    EXPECT_NEAR(bin.j, std::sqrt(R), 1e-12);
    EXPECT_NEAR(bin.vr, 0.0, 1e-12);
  }
  EXPECT_EQ(d.bins[0].count + d.bins[2].count, 0u);
  EXPECT_NE(disc_profiles_table(d).find("z_rms/R"), std::string::npos);
  EXPECT_NE(disc_profiles_json(d).find("\"z_rms\""), std::string::npos);
  const DiscProfiles flat = disc_profiles(seen_from_above(p3), SnapshotMeta{}, 4, 1.0, 3.0);
  EXPECT_FALSE(flat.heights);
  EXPECT_EQ(disc_profiles_table(flat).find("z_rms"), std::string::npos);
}
