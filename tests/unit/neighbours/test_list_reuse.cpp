// Neighbour-list reuse (neighbours/list_reuse.hpp, RateEvaluator::set_list_skin): the reuse test is
// checked against brute force (whenever it keeps lists, no interacting pair is missing from them),
// it keeps lists under large motion that is the same for all particles, and rates from reused
// lists equal those from fresh lists.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <utility>

#include <gtest/gtest.h>

#include "app/rate_evaluator.hpp"
#include "neighbours/cell_grid.hpp"
#include "neighbours/list_reuse.hpp"
#include "parallel/loops.hpp"
#include "test_helpers.hpp"

namespace sphdisk {
namespace {

// Whether some pair interacts now (closer than support(i)) that i's list lacks (it was no closer
// than listed(i) at build time): brute force over all pairs.
template <int D>
bool pair_missing(const std::vector<Vec<D>>& pos0, const std::vector<Vec<D>>& pos, const std::vector<double>& listed,
                  const std::vector<double>& support) {
  for (std::size_t i = 0; i < pos.size(); ++i)
    for (std::size_t j = 0; j < pos.size(); ++j)
      if (i != j && norm(pos[i] - pos[j]) < support[i] && norm(pos0[i] - pos0[j]) >= listed[i]) return true;
  return false;
}

// Random particles with radii varying by +-30% (and, with `wide` > 0, that fraction of them with
// radii five times larger, as sparse particles among dense ones, and slacks from 15% to 45% of the
// typical radius whatever the radius), moved by a shear flow, random
// jitter and a large translation of all of them, of growing size. Every verdict "valid" must be
// right; small motion must be accepted and large motion must produce missing pairs (so both
// branches are exercised).
template <int D>
void check_reuse_against_brute_force(unsigned seed, double wide = 0.0) {
  const std::size_t n = D == 2 ? 1500 : 1200;
  const auto p = test::random_particles<D>(n, seed, true);
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double s0 = D == 2 ? 0.05 : 0.12;
  std::vector<double> support0(n), listed(n);
  for (std::size_t i = 0; i < n; ++i) {
    support0[i] = s0 * (1.0 + 0.3 * u(g)) * (0.5 * (u(g) + 1.0) < wide ? 5.0 : 1.0);
    // With wide ones, slacks vary independently of the supports (as h solves leave them).
    listed[i] = support0[i] + (wide > 0 ? s0 * (0.15 + 0.15 * (u(g) + 1.0)) : 0.25 * support0[i]);
  }
  CellGrid<D> grid;
  build_cell_grid(p.pos, p.id, 0.5 * s0, grid);  // cells smaller than most radii: any size works
  ListReuse<D> reuse;
  reuse.record(grid, p.pos, p.id);
  ASSERT_TRUE(reuse.same_particles(p.id));

  int accepted = 0, rejected_with_missing_pair = 0;
  for (int trial = 0; trial < 24; ++trial) {
    const double size = 0.002 * std::pow(1.4, trial);  // relative motion from 0.04 to ~50 x the skin
    std::vector<Vec<D>> pos(p.pos);
    std::vector<double> support(support0);
    Vec<D> shift;
    for (int k = 0; k < D; ++k) shift[k] = 10.0 * u(g);
    for (std::size_t i = 0; i < n; ++i) {
      pos[i] += shift;
      pos[i][0] += size * 2.0 * p.pos[i][1];  // shear
      for (int k = 0; k < D; ++k) pos[i][k] += 0.2 * size * u(g);
      support[i] *= 1.0 + (wide > 0 ? 0.004 : 0.02) * u(g);  // wide ones: 2% of s0
    }
    const auto v = reuse.check(grid, pos, [&](std::size_t i) { return listed[i]; },
                               [&](std::size_t i) { return support[i]; });
    const bool missing = pair_missing<D>(p.pos, pos, listed, support);
    if (v.valid) {
      ++accepted;
      EXPECT_FALSE(missing) << "trial " << trial << ": lists kept although a pair is missing (used " << v.used << ")";
      EXPECT_LT(v.used, 1.0);
    } else {
      EXPECT_GE(v.used, 1.0);
      rejected_with_missing_pair += missing;
    }
  }
  EXPECT_GE(accepted, 3);
  EXPECT_GE(rejected_with_missing_pair, 3);
}

TEST(ListReuse, NeverKeepsListsThatMissAPair2D) { check_reuse_against_brute_force<2>(31); }
TEST(ListReuse, NeverKeepsListsThatMissAPair3D) { check_reuse_against_brute_force<3>(32); }
TEST(ListReuse, NeverKeepsListsThatMissAPairWideAmongNarrow2D) { check_reuse_against_brute_force<2>(37, 0.05); }
TEST(ListReuse, NeverKeepsListsThatMissAPairWideAmongNarrow3D) { check_reuse_against_brute_force<3>(38, 0.05); }

// A sparse particle whose wide support reaches into a dense clump (the ring's inner edge): the
// clump's narrow supports cannot reach the sparse particle, so their motion against it is held
// against the sparse particle's slack only. The lists are kept while the clump moves by less than
// that slack (fifteen times the clump's own), and rejected when it comes closer by more, which
// brings unlisted pairs within the wide support.
TEST(ListReuse, WideSupportIsHeldAgainstItsOwnSlack) {
  Particles<2> p;
  const std::size_t columns = 13, rows = 3;  // 0.01 apart, from x = 0.28 to 0.40: listed up to 0.375
  p.resize(1 + columns * rows);
  p.pos[0] = Vec<2>{{0.0, 0.0}};
  for (std::size_t k = 0; k < columns * rows; ++k)
    p.pos[1 + k] = Vec<2>{{0.28 + 0.01 * static_cast<double>(k % columns), 0.01 * static_cast<double>(k / columns)}};
  for (std::size_t i = 0; i < p.size(); ++i) p.id[i] = 10 + i;
  std::vector<double> support(p.size(), 0.02), listed(p.size());
  support[0] = 0.3;
  for (std::size_t i = 0; i < p.size(); ++i) listed[i] = 1.25 * support[i];  // slack 0.075 and 0.005
  CellGrid<2> grid;
  build_cell_grid(p.pos, p.id, 0.02, grid);
  ListReuse<2> reuse;
  reuse.record(grid, p.pos, p.id);
  for (const double move : {0.01, -0.01, 0.05, -0.05, 0.07, -0.07, -0.1}) {  // the clump moves along x
    std::vector<Vec<2>> now(p.pos);
    for (std::size_t k = 1; k < now.size(); ++k) now[k][0] += move;
    const auto v = reuse.check(grid, now, [&](std::size_t i) { return listed[i]; }, [&](std::size_t i) { return support[i]; });
    const bool missing = pair_missing<2>(p.pos, now, listed, support);
    EXPECT_EQ(v.valid, std::abs(move) < 0.075) << "moved " << move << " (used " << v.used << ")";
    EXPECT_EQ(missing, move < -0.075) << "moved " << move;  // the test's premise
  }
}

// The converse: a narrow particle sharing a cell with a wide one still holds close motion against
// its own small slack. M approaches N from beyond N's listed radius; M's list and that of the wide
// particle W beside N hold the pair anyway, N's (its candidates for the h solve) does not.
TEST(ListReuse, NarrowSlackStillCountsNearby) {
  Particles<2> p;
  p.resize(3);
  p.id = {1, 2, 3};
  p.pos = {Vec<2>{{0.0, 0.0}}, Vec<2>{{0.01, 0.0}}, Vec<2>{{0.03, 0.0}}};  // N, W, M
  const std::vector<double> support = {0.02, 0.3, 0.02}, listed = {0.025, 0.4, 0.05};
  CellGrid<2> grid;
  build_cell_grid(p.pos, p.id, 0.02, grid);
  ListReuse<2> reuse;
  reuse.record(grid, p.pos, p.id);
  for (const double x : {0.027, 0.015}) {  // M moves by less, then by more than N's slack
    std::vector<Vec<2>> now(p.pos);
    now[2][0] = x;
    const auto v = reuse.check(grid, now, [&](std::size_t i) { return listed[i]; }, [&](std::size_t i) { return support[i]; });
    const bool missing = pair_missing<2>(p.pos, now, listed, support);
    EXPECT_EQ(missing, x < 0.02) << "M at " << x;  // the test's premise
    EXPECT_EQ(v.valid, !missing) << "M at " << x << " (used " << v.used << ")";
  }
}

TEST(ListReuse, AnotherParticleOrderIsNotTheSameParticles) {
  auto p = test::random_particles<2>(100, 34, false);
  CellGrid<2> grid;
  build_cell_grid(p.pos, p.id, 0.1, grid);
  ListReuse<2> reuse;
  EXPECT_FALSE(reuse.same_particles(p.id));  // nothing recorded
  reuse.record(grid, p.pos, p.id);
  EXPECT_TRUE(reuse.same_particles(p.id));
  std::swap(p.id[3], p.id[40]);
  EXPECT_FALSE(reuse.same_particles(p.id));
  p.id.pop_back();
  EXPECT_FALSE(reuse.same_particles(p.id));
}

// The pair lists the evaluator's loops read hold exactly the pairs closer than the larger of their
// two supports, each once: none missing, and none of the skin's (pair_lists.hpp,
// keep_interacting_pairs).
void expect_exactly_the_interacting_pairs(const Particles<2>& p, const PairLists& pl, int step) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> listed;  // read serially (for_each_pair runs on threads)
  for (const NeighbourLists* half : {&pl.near, &pl.far})
    for (std::uint32_t k = 0; k < half->size(); ++k)  // list k is particle order[k]'s
      for (const std::uint32_t* j = half->begin(k); j != half->end(k); ++j) {
        const std::uint32_t i = pl.order[k];
        listed.insert({std::min(i, *j), std::max(i, *j)});
      }
  ASSERT_EQ(listed.size(), pl.total()) << "step " << step << ": a pair listed twice";
  std::size_t interacting = 0;
  for (std::uint32_t i = 0; i < p.size(); ++i)
    for (std::uint32_t j = i + 1; j < p.size(); ++j)
      if (norm(p.pos[i] - p.pos[j]) < 2.0 * std::max(p.h[i], p.h[j])) {
        ++interacting;
        ASSERT_TRUE(listed.count({i, j})) << "step " << step << ": pair " << i << ", " << j << " missing";
      }
  EXPECT_EQ(listed.size(), interacting) << "step " << step << ": pairs beyond the supports listed";
}

// Rates from reused lists equal those of a fresh evaluation at the same positions, while the
// particles drift in a shear flow; the lists are in fact reused, and rebuilt once the motion is too
// large. To round-off with one h (the pairs are summed in the cell order of the build); with
// adaptive h the Newton solve stops once its step is below 1e-4 of h, so h (and what depends on
// it) is exact to about the square of that and the two solves may stop one iteration apart.
void check_rates_with_reused_lists(Smoothing smoothing, double tolerance) {
  auto p = test::square_lattice(48, 0.02);
  std::mt19937_64 g(35);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (auto& x : p.pos) x += Vec<2>{{0.004 * u(g), 0.004 * u(g)}};
  for (std::size_t i = 0; i < p.size(); ++i) p.vel[i] = Vec<2>{{1.5 * p.pos[i][1], 0.2 * p.pos[i][0]}};
  std::fill(p.h.begin(), p.h.end(), 0.025);
  PhysicsParams phys;
  phys.nu = 0.01;
  phys.gm = 0.0;
  PhaseTimers timers;
  RateEvaluator<2> reused(KernelType::Cubic, 0.025, phys, timers, smoothing, 50);
  reused.set_list_skin(0.3);
  const double dt = 0.004;  // shear displacement per step across a support: 0.6% of the support
  for (int step = 0; step < 12; ++step) {
    if (step > 0)
      for (std::size_t i = 0; i < p.size(); ++i) p.pos[i] += p.vel[i] * (step == 8 ? 40.0 * dt : dt);  // step 8 jumps
    Particles<2> q = p;  // the same start values of h
    reused.evaluate(p);
    expect_exactly_the_interacting_pairs(p, reused.pair_lists(), step);
    RateEvaluator<2> fresh(KernelType::Cubic, 0.025, phys, timers, smoothing, 50);
    fresh.evaluate(q);
    double worst = 0, scale = 0;
    for (std::size_t i = 0; i < p.size(); ++i) scale = std::max(scale, norm(q.acc[i]));
    for (std::size_t i = 0; i < p.size(); ++i) {
      ASSERT_NEAR(p.h[i], q.h[i], tolerance * q.h[i]) << "step " << step << " particle " << i;
      // rho as stored: with single-precision fields the two roundings may be one unit apart
      const double stored = std::numeric_limits<ReducedReal>::epsilon();
      ASSERT_NEAR(p.rho[i], q.rho[i], (tolerance + stored) * q.rho[i]) << "step " << step << " particle " << i;
      worst = std::max(worst, norm(p.acc[i] - q.acc[i]));
    }
    EXPECT_LT(worst, 100 * tolerance * scale) << "step " << step;
  }
  EXPECT_EQ(reused.evaluations(), 12u);
  EXPECT_LT(reused.list_builds(), 6u);  // reused most of the time
  EXPECT_GE(reused.list_builds(), 2u);  // and rebuilt after the jump
}

TEST(ListReuse, RatesEqualFreshListsConstantH) { check_rates_with_reused_lists(Smoothing::Constant, 1e-12); }
TEST(ListReuse, RatesEqualFreshListsAdaptiveH) { check_rates_with_reused_lists(Smoothing::Adaptive, 1e-7); }

// Reuse decisions depend on positions only: the same bits for any thread count.
TEST(ListReuse, SameBitsForAnyThreadCount) {
  std::vector<std::vector<Vec<2>>> acc;
  std::vector<std::size_t> builds;
  for (int threads : {1, 2, 3}) {
    par::set_threads(threads);
    auto p = test::random_particles<2>(2000, 36, false);
    for (std::size_t i = 0; i < p.size(); ++i) p.vel[i] = Vec<2>{{0.5 * p.pos[i][1], 0.0}};
    std::fill(p.h.begin(), p.h.end(), 0.03);
    PhysicsParams phys;
    phys.nu = 0.01;
    phys.gm = 0.0;
    PhaseTimers timers;
    RateEvaluator<2> rates(KernelType::Cubic, 0.03, phys, timers, Smoothing::Adaptive, 50);
    rates.set_list_skin(0.25);
    for (int step = 0; step < 6; ++step) {
      for (std::size_t i = 0; i < p.size(); ++i) p.pos[i] += p.vel[i] * 0.002;
      rates.evaluate(p);
    }
    acc.push_back(p.acc);
    builds.push_back(rates.list_builds());
  }
  par::set_threads(0);
  EXPECT_LT(builds[0], 6u);
  for (std::size_t t = 1; t < acc.size(); ++t) {
    EXPECT_EQ(builds[t], builds[0]);
    for (std::size_t i = 0; i < acc[0].size(); ++i) {
      ASSERT_EQ(acc[t][i][0], acc[0][i][0]);
      ASSERT_EQ(acc[t][i][1], acc[0][i][1]);
    }
  }
}

}  // namespace
}  // namespace sphdisk
