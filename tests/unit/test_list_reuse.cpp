// Neighbour-list reuse (neighbours/list_reuse.hpp, RateEvaluator::set_list_skin): the reuse test is
// checked against brute force (whenever it keeps lists, no interacting pair is missing from them),
// it keeps lists under large motion that is the same for all particles, and rates from reused
// lists equal those from fresh lists.
#include <algorithm>
#include <cmath>
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

// Random particles with radii varying by +-30%, moved by a shear flow, random jitter and a large
// translation of all of them, of growing size. Every verdict "valid" must be right; small motion
// must be accepted and large motion must produce missing pairs (so both branches are exercised).
template <int D>
void check_reuse_against_brute_force(unsigned seed) {
  const std::size_t n = D == 2 ? 1500 : 1200;
  const auto p = test::random_particles<D>(n, seed, true);
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double s0 = D == 2 ? 0.05 : 0.12;
  std::vector<double> support0(n), listed(n);
  for (std::size_t i = 0; i < n; ++i) {
    support0[i] = s0 * (1.0 + 0.3 * u(g));
    listed[i] = 1.25 * support0[i];
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
      support[i] *= 1.0 + 0.02 * u(g);
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

// A translation of all particles by a hundred supports is no relative motion: lists stay; so
// does a slow rigid rotation of the whole set about a far-away point (the disc's case: fast orbits,
// slow shear).
TEST(ListReuse, LargeCommonMotionKeepsTheLists) {
  const auto p = test::random_particles<2>(2000, 33, false);
  const double support = 0.04;
  CellGrid<2> grid;
  build_cell_grid(p.pos, p.id, 0.6 * support, grid);
  ListReuse<2> reuse;
  reuse.record(grid, p.pos, p.id);
  const auto listed = [&](std::size_t) { return 1.2 * support; };
  const auto now = [&](std::size_t) { return support; };

  std::vector<Vec<2>> moved(p.pos);
  for (auto& x : moved) x += Vec<2>{{3.0, -4.0}};
  const auto translated = reuse.check(grid, moved, listed, now);
  EXPECT_TRUE(translated.valid);
  EXPECT_LT(translated.used, 1e-9);

  const double angle = 1e-4;  // about (20, 0): the particles move by ~2e-3 = 5% of the support
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec<2> r = p.pos[i] - Vec<2>{{20.0, 0.0}};
    moved[i] = Vec<2>{{20.0 + std::cos(angle) * r[0] - std::sin(angle) * r[1], std::sin(angle) * r[0] + std::cos(angle) * r[1]}};
  }
  const auto rotated = reuse.check(grid, moved, listed, now);
  EXPECT_TRUE(rotated.valid);
  EXPECT_LT(rotated.used, 0.01);
  EXPECT_FALSE(pair_missing<2>(p.pos, moved, std::vector<double>(p.size(), 1.2 * support), std::vector<double>(p.size(), support)));
}

// Two particles, unlisted at build time, approach each other: from just beyond the listed radius,
// and from far away (cells that were never neighbours). The test rejects the lists once they come
// within the support, and only then.
TEST(ListReuse, ApproachingPairIsCaught) {
  const double support = 0.1, listed = 0.125;
  for (const double start : {0.13, 0.5, 3.0}) {
    for (const double end : {0.02, 0.07, 0.099, 0.12}) {
      Particles<2> p;
      p.resize(2);
      p.id = {7, 8};
      p.pos = {Vec<2>{{0.0, 0.0}}, Vec<2>{{start, 0.3 * start}}};
      CellGrid<2> grid;
      build_cell_grid(p.pos, p.id, 0.5 * support, grid);
      ListReuse<2> reuse;
      reuse.record(grid, p.pos, p.id);
      std::vector<Vec<2>> now = {Vec<2>{{0.0, 0.0}}, p.pos[1] * (end / norm(p.pos[1]))};
      const auto v = reuse.check(grid, now, [&](std::size_t) { return listed; }, [&](std::size_t) { return support; });
      // With one particle per cell the bound is exact: kept exactly when the pair does not interact
      // (closer than the support only after moving by more than the skin, from >= listed).
      EXPECT_EQ(v.valid, end >= support) << "from " << start << " to " << end;
    }
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

// Every pair closer than the larger of its two supports is in the evaluator's pair lists.
void expect_every_interacting_pair_listed(const Particles<2>& p, const PairLists& pl, int step) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> listed;  // read serially (for_each_pair runs on threads)
  for (const NeighbourLists* half : {&pl.near, &pl.far})
    for (std::uint32_t i = 0; i < half->size(); ++i)
      for (const std::uint32_t* j = half->begin(i); j != half->end(i); ++j) listed.insert({std::min(i, *j), std::max(i, *j)});
  for (std::uint32_t i = 0; i < p.size(); ++i)
    for (std::uint32_t j = i + 1; j < p.size(); ++j)
      if (norm(p.pos[i] - p.pos[j]) < 2.0 * std::max(p.h[i], p.h[j]))
        ASSERT_TRUE(listed.count({i, j})) << "step " << step << ": pair " << i << ", " << j << " missing";
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
    expect_every_interacting_pair_listed(p, reused.pair_lists(), step);
    RateEvaluator<2> fresh(KernelType::Cubic, 0.025, phys, timers, smoothing, 50);
    fresh.evaluate(q);
    double worst = 0, scale = 0;
    for (std::size_t i = 0; i < p.size(); ++i) scale = std::max(scale, norm(q.acc[i]));
    for (std::size_t i = 0; i < p.size(); ++i) {
      ASSERT_NEAR(p.h[i], q.h[i], tolerance * q.h[i]) << "step " << step << " particle " << i;
      ASSERT_NEAR(p.rho[i], q.rho[i], tolerance * q.rho[i]) << "step " << step << " particle " << i;
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
