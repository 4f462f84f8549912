// The block steps' drift of all particles (integrate/orbit_drift.hpp) against the per-particle
// routines it stands in for, bit for bit, on every vector path: drift_in_point_mass_field and the
// stress turn of turned_with_orbit, with particles that need one gravity substep and others (close
// to the point mass) that need several.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "integrate/orbit_drift.hpp"
#include "integrate/point_mass_drift.hpp"
#include "test_helpers.hpp"

namespace sphdisk {
namespace {

struct Drifted {
  std::vector<Vec<2>> x, v;
  std::vector<Mat<2, ReducedReal>> S;
};

Drifted start(std::size_t n) {
  std::mt19937_64 g(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Drifted d;
  for (std::size_t k = 0; k < n; ++k) {
    // radii from 0.02 to ~1.4: the inner ones need several substeps over dt below
    const double scale = k % 7 == 0 ? 0.02 : 1.0;
    const Vec<2> x{scale * u(g), scale * u(g)};
    d.x.push_back(x);
    d.v.push_back(Vec<2>{-x[1], x[0]} * (1.0 / std::pow(norm(x) + 1e-3, 1.5)) + Vec<2>{0.01 * u(g), 0.01 * u(g)});
    Mat<2, ReducedReal> S;
    for (auto& c : S.c) c = static_cast<ReducedReal>(u(g));
    d.S.push_back(S);
  }
  return d;
}

bool same_bits(const void* a, const void* b, std::size_t bytes) { return std::memcmp(a, b, bytes) == 0; }

TEST(OrbitDrift, EqualsThePerParticleRoutinesOnEveryPath) {
  const std::size_t n = 1003;  // not a multiple of any vector width
  const double dt = 2e-3, gm = 1.0, factor = 0.05;
  Drifted expected = start(n);
  std::size_t several = 0, few = 0, many = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const Vec<2> from = expected.x[k];
    const double substeps = std::ceil(dt / orbital_timestep(norm(from), gm, factor));
    several += substeps > 1;
    few += substeps > 1 && substeps <= 4;  // in the vector loops' further passes
    many += substeps > 100;                // beyond them: the general routine
    drift_in_point_mass_field(expected.x[k], expected.v[k], dt, gm, factor);
    expected.S[k] = turned_with_orbit(expected.S[k], from, expected.x[k]);
  }
  ASSERT_GT(several, 50u);       // some particles take several substeps
  ASSERT_LT(several, n / 2);     // most take one
  ASSERT_GT(few, 5u);            // (the vector loops take a few substeps, orbit_drift.cpp:
  ASSERT_GT(many, 5u);           // kFewSubsteps, and leave more to the general routine)
  std::vector<VectorIsa> paths = test::vector_paths();
  paths.insert(paths.begin(), VectorIsa::baseline);
  for (const VectorIsa isa : paths) {
    SCOPED_TRACE(vector_isa_name(isa));
    Drifted got = start(n);
    test::on_path(isa, [&] {
      drift_and_turn<2>(got.x.data(), got.v.data(), got.S.data(), n, dt, gm, factor);
      return 0;
    });
    EXPECT_TRUE(same_bits(got.x.data(), expected.x.data(), n * sizeof(Vec<2>)));
    EXPECT_TRUE(same_bits(got.v.data(), expected.v.data(), n * sizeof(Vec<2>)));
    EXPECT_TRUE(same_bits(got.S.data(), expected.S.data(), n * sizeof(Mat<2, ReducedReal>)));
  }
}

// The turn, written out for the rotation about z, against the general product R S R^T: the same
// values (a zero may differ in its sign), in 3D with the z row and column carried through.
template <int D>
void check_turn_is_the_rotations_product() {
  std::mt19937_64 g(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    Mat<D, ReducedReal> S;
    for (auto& c : S.c) c = static_cast<ReducedReal>(u(g));
    Vec<D> from, to;
    for (int k = 0; k < D; ++k) from[k] = u(g), to[k] = u(g);
    const double norms = std::sqrt((from[0] * from[0] + from[1] * from[1]) * (to[0] * to[0] + to[1] * to[1]));
    const double c = (from[0] * to[0] + from[1] * to[1]) / norms, s = (from[0] * to[1] - from[1] * to[0]) / norms;
    Mat<D> R = identity<D>(), Rt = identity<D>();
    R(0, 0) = c, R(0, 1) = -s, R(1, 0) = s, R(1, 1) = c;
    Rt(0, 0) = c, Rt(0, 1) = s, Rt(1, 0) = -s, Rt(1, 1) = c;
    Mat<D, ReducedReal> expected;
    store(expected, R * as_double(S) * Rt);
    const Mat<D, ReducedReal> got = turned_with_orbit(S, from, to);
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j) ASSERT_EQ(got(i, j), expected(i, j)) << D << "D, trial " << trial << ", (" << i << ", " << j << ")";
    if constexpr (D == 3) ASSERT_EQ(got(2, 2), S(2, 2));
  }
  // At the origin nothing is turned.
  Mat<D, ReducedReal> S;
  for (auto& c : S.c) c = static_cast<ReducedReal>(u(g));
  Vec<D> origin{}, elsewhere{};
  elsewhere[0] = 1.0;
  const Mat<D, ReducedReal> same = turned_with_orbit(S, origin, elsewhere);
  for (std::size_t k = 0; k < S.c.size(); ++k) ASSERT_EQ(same.c[k], S.c[k]);
}

TEST(OrbitDrift, TurnIsTheRotationsProduct) {
  check_turn_is_the_rotations_product<2>();
  check_turn_is_the_rotations_product<3>();
}

}  // namespace
}  // namespace sphdisk
