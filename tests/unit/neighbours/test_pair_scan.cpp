// Pair loops without stored lists (neighbours/pair_scan.hpp, sph.pair_lists = "rescan"): every
// pair with |x_i - x_j| < 2 max(h_i, h_j) and a writable particle exactly once (brute force, 2D and
// 3D, varying h, far pairs, unwritable particles), tiles of one colour far enough apart to write to
// disjoint particles, the same order of pair terms for any thread count, and rates equal to those
// of stored lists.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <utility>

#include "evaluate/rate_evaluator.hpp"
#include "neighbours/pair_scan.hpp"
#include "parallel/loops.hpp"
#include "test_helpers.hpp"

using namespace sphdisk;

namespace {

// Particles with smoothing lengths h0 (equal_h) or h0 x [0.6, 1.4) with every `wide_every`-th
// particle's eight times wider (supports wider than a tile: far pairs).
template <int D>
Particles<D> with_smoothing_lengths(Particles<D> p, double h0, bool equal_h, unsigned seed, std::size_t wide_every = 50) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0.6, 1.4);
  for (std::size_t i = 0; i < p.size(); ++i) p.h[i] = equal_h ? h0 : h0 * u(g) * (i % wide_every == 7 ? 8.0 : 1.0);
  return p;
}

template <int D>
struct ScanSetup {
  Particles<D> p;
  CellGrid<D> grid;
  PairLists tiles;
  CandidateFilter writable_filter;
  bool equal_h;
  ScanSetup(Particles<D> particles, double h0, bool equal, std::size_t writable, int tile_cells)
      : p(std::move(particles)), equal_h(equal) {
    build_cell_grid(p.pos, p.id, h0, grid);
    build_tile_order(grid, tile_cells, writable, tiles, TileWrites::AllNeighbours);
    writable_filter.build(grid, p.pos, writable);
  }
  // A factor that tells the pair apart from others (to check what FactorUse::Read hands over).
  static double factor(std::uint32_t i, std::uint32_t j, double r) { return r + 1e-3 * (i + j); }
  // g(pairs) with the ScannedPairs of this set (made anew for each call, as for each evaluation).
  template <class G>
  void with_pairs(G&& g) const {
    const auto form = [](std::uint32_t i, std::span<const std::uint32_t> js, const double* r2, std::span<float> F) {
      for (std::size_t q = 0; q < js.size(); ++q) F[q] = static_cast<float>(factor(i, js[q], std::sqrt(r2[q])));
    };
    const ScannedPairs<D, decltype(form)> pairs(grid, tiles, p.h, equal_h, writable_filter, form);
    g(pairs);
  }
  template <class F>
  void for_each_list(F&& f, FactorUse use) const {
    with_pairs([&](const auto& pairs) { pairs.for_each_list(f, use); });
  }
  // The pair count an evaluation reports after its loops (here two): each pair counted once.
  std::size_t pairs_found_after_two_loops() const {
    std::size_t found = 0;
    with_pairs([&](const auto& pairs) {
      const auto nothing = [](std::uint32_t, std::span<const std::uint32_t>, std::span<float>) {};
      pairs.for_each_list(nothing, FactorUse::Read);
      pairs.for_each_list(nothing, FactorUse::Write);
      found = pairs.pairs_found();
    });
    return found;
  }
};

template <int D>
void check_every_pair_once(Particles<D> particles, double h0, bool equal_h, std::size_t writable, int tile_cells,
                           bool expect_far, std::size_t wide_every = 50) {
  ScanSetup<D> s(with_smoothing_lengths(std::move(particles), h0, equal_h, 5, wide_every), h0, equal_h, writable,
                 tile_cells);
  const std::size_t n = s.p.size();
  std::set<std::pair<std::uint32_t, std::uint32_t>> expected;
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::uint32_t j = i + 1; j < n; ++j) {
      const double support = 2.0 * std::max(s.p.h[i], s.p.h[j]);
      if ((i < writable || j < writable) && norm2(s.p.pos[i] - s.p.pos[j]) < support * support) expected.insert({i, j});
    }
  ASSERT_GT(expected.size(), n);  // dense enough to mean something
  par::set_threads(1);  // the visits are recorded in one container
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> visits;
  std::size_t far = 0;
  bool factors_right = true;
  s.for_each_list([&](std::uint32_t i, std::span<const std::uint32_t> js, std::span<float> F) {
    ASSERT_EQ(F.size(), js.size());
    for (std::size_t q = 0; q < js.size(); ++q) {
      const std::uint32_t j = js[q];
      ++visits[{std::min(i, j), std::max(i, j)}];
      far += !tiles_adjacent<D>(s.tiles.tile.data() + D * i, s.tiles.tile.data() + D * j);
      factors_right &= F[q] == static_cast<float>(ScanSetup<D>::factor(i, j, norm(s.p.pos[i] - s.p.pos[j])));
    }
  }, FactorUse::Read);
  par::set_threads(0);
  std::set<std::pair<std::uint32_t, std::uint32_t>> got;
  for (const auto& [pair, count] : visits) {
    EXPECT_EQ(count, 1) << "pair " << pair.first << ", " << pair.second << " visited " << count << " times";
    got.insert(pair);
  }
  EXPECT_EQ(got, expected);
  // The per-particle factors are formed only for the particles may_read names: every particle of a
  // visited pair must be one of them.
  bool all_named = true;
  s.with_pairs([&](const auto& pairs) {
    for (const auto& [pair, count] : visits) all_named &= pairs.may_read(pair.first) && pairs.may_read(pair.second);
  });
  EXPECT_TRUE(all_named) << "a loop read a particle that may_read leaves out";
  EXPECT_EQ(s.pairs_found_after_two_loops(), expected.size());
  EXPECT_TRUE(factors_right) << "FactorUse::Read must hand over the factors formed at each pair's distance";
  if (expect_far) EXPECT_GT(far, 0u);
  else EXPECT_EQ(far, 0u);
}

}  // namespace

TEST(PairScan, EveryPairOnceWithOneSmoothingLength) {
  check_every_pair_once(test::random_particles<2>(1500, 41, true), 0.02, true, 1500, 4, false);
  check_every_pair_once(test::random_particles<3>(1500, 42, false), 0.06, true, 1500, 2, false);
}
TEST(PairScan, EveryPairOnceWithVaryingSmoothingLengths) {
  check_every_pair_once(test::random_particles<2>(1500, 43, true), 0.015, false, 1500, 16, false);
  check_every_pair_once(test::random_particles<3>(1500, 44, false), 0.05, false, 1500, 16, false);
}
// Every 50th particle's support spans several one- or two-cell tiles: its far pairs come after the colours.
TEST(PairScan, PairsBeyondTheAdjacentTilesOnce) {
  check_every_pair_once(test::random_particles<2>(1500, 45, true), 0.015, false, 1500, 1, true);
  check_every_pair_once(test::random_particles<3>(1500, 46, false), 0.05, false, 1500, 2, true);
}
// A few wide particles among many: the far pairs are looked for only in the tiles that hold one
// (ScannedPairs::summarise_tiles), and none may be missed.
TEST(PairScan, FewWideParticlesFarPairsOnce) {
  check_every_pair_once(test::random_particles<2>(5000, 51, true), 0.008, false, 5000, 1, true, 1200);
}
// The writable particles in a strip along one edge (as the active particles of block steps crowd
// the centre): tiles with none of them within reach are skipped whole, and the unwritable
// particles next to the strip, in tiles of their own, still give their pairs with it.
TEST(PairScan, TilesFarFromWritableParticlesSkippedWithoutLosingPairs) {
  for (const unsigned seed : {52u, 53u}) {
    Particles<2> p = test::random_particles<2>(4000, seed, false);
    std::sort(p.pos.begin(), p.pos.end(), [](const Vec<2>& a, const Vec<2>& b) { return a[0] < b[0]; });
    check_every_pair_once(std::move(p), 0.015, false, 600, 2, true, 300);
  }
}
// With few writable particles in a strip, may_read names each particle a loop reads (checked in
// check_every_pair_once) and leaves out most of the others, whose factors are then not formed.
TEST(PairScan, MayReadLeavesOutParticlesFarFromWritableOnes) {
  Particles<2> p = with_smoothing_lengths(test::random_particles<2>(4000, 54, false), 0.015, false, 5, 300);
  std::sort(p.pos.begin(), p.pos.end(), [](const Vec<2>& a, const Vec<2>& b) { return a[0] < b[0]; });
  const ScanSetup<2> s(std::move(p), 0.015, false, 200, 2);
  std::size_t named = 0, near = 0;
  s.with_pairs([&](const auto& pairs) {
    for (std::uint32_t i = 0; i < 4000; ++i) named += pairs.may_read(i);
  });
  double widest = 0, right = -1e300;  // the writable strip's right edge and widest h
  for (std::uint32_t i = 0; i < 200; ++i) widest = std::max(widest, s.p.h[i]), right = std::max(right, s.p.pos[i][0]);
  for (std::uint32_t i = 0; i < 4000; ++i) near += s.p.pos[i][0] < right + 2.0 * std::max(widest, s.p.h[i]);
  EXPECT_GE(named, near);  // at least those within reach of the strip (the test is by cells: a few more)
  EXPECT_LT(named, 4000u / 2) << "may_read should leave out the particles far from the strip";
}

// Particles from `writable` on (ghosts, inactive particles) only count with writable partners.
TEST(PairScan, PairsOfTwoUnwritableParticlesLeftOut) {
  check_every_pair_once(test::random_particles<2>(1500, 47, true), 0.015, false, 600, 2, true);
  check_every_pair_once(test::random_particles<2>(1500, 48, false), 0.02, true, 900, 4, false);
  check_every_pair_once(test::random_particles<3>(1500, 49, true), 0.05, false, 700, 2, true);
}

// A sum whose bits depend on the order of its terms comes out the same on 1-4 threads.
TEST(PairScan, SameOrderOfPairTermsForAnyThreadCount) {
  ScanSetup<2> s(with_smoothing_lengths(test::random_particles<2>(4000, 52, true), 0.01, false, 5), 0.01, false, 3000, 1);
  auto sums = [&](int threads) {
    par::set_threads(threads);
    std::vector<double> acc(s.p.size(), 0.0);
    s.for_each_list([&](std::uint32_t i, std::span<const std::uint32_t> js, std::span<float>) {
      for (const std::uint32_t j : js) {
        const double t = 1.0 / (1.0 + 1e3 * norm2(s.p.pos[i] - s.p.pos[j])) + 1e-9 * i;
        acc[i] = acc[i] * 0.999 + t;  // not associative: any change of order changes the bits
        acc[j] = acc[j] * 0.999 - t;
      }
    }, FactorUse::Write);
    par::set_threads(0);
    return acc;
  };
  const auto one = sums(1);
  for (int threads : {2, 3, 4}) EXPECT_EQ(sums(threads), one) << threads << " threads";
}

// The two loops joined (for_each_list_joined, tile_jobs.hpp) hand every particle the terms of the
// loops run one after the other (the first with the far pairs first, the second with them last), in
// the same order, for any thread count; each writable particle is settled once, after every term of
// the first loop that reaches it, and before any term of the second that reaches it or its partner.
// The terms are recorded per particle without locks: jobs that ran together on common particles
// would lose or reorder them. Varying h with wide particles (far pairs), 3,000 of 4,000 writable.
TEST(PairScan, JoinedLoopsGiveTheSeparateLoopsTermsInOrder) {
  ScanSetup<2> s(with_smoothing_lengths(test::random_particles<2>(4000, 57, true), 0.01, false, 5), 0.01, false, 3000, 1);
  const std::size_t n = s.p.size(), m = 3000;
  using Terms = std::vector<std::vector<std::uint32_t>>;  // per particle: its partners, in order
  const auto record = [](Terms& into, std::uint32_t i, std::span<const std::uint32_t> js) {
    for (const std::uint32_t j : js) {
      into[i].push_back(j);
      into[j].push_back(i);
    }
  };
  Terms first_apart(n), second_apart(n);
  s.with_pairs([&](const auto& pairs) {
    pairs.for_each_list([&](std::uint32_t i, std::span<const std::uint32_t> js, std::span<float>) { record(first_apart, i, js); },
                        FactorUse::Read, {}, FarPairs::First);
    pairs.for_each_list([&](std::uint32_t i, std::span<const std::uint32_t> js, std::span<float>) { record(second_apart, i, js); },
                        FactorUse::Read, {}, FarPairs::Last);
  });
  for (int threads : {1, 3}) {
    par::set_threads(threads);
    Terms first(n), second(n);
    std::vector<int> settled(n, 0);
    std::vector<std::size_t> seen_when_settled(n, 0);
    bool settled_in_time = true;
    s.with_pairs([&](const auto& pairs) {
      pairs.for_each_list_joined(
          [&](std::uint32_t i, std::span<const std::uint32_t> js, std::span<float>) {
            for (const std::uint32_t j : js) settled_in_time &= !settled[i] && !settled[j];
            record(first, i, js);
          },
          [&](std::uint32_t i) {
            ++settled[i];
            seen_when_settled[i] = first[i].size();
          },
          [&](std::uint32_t i, std::span<const std::uint32_t> js, std::span<float>) {
            for (const std::uint32_t j : js) settled_in_time &= (i >= m || settled[i]) && (j >= m || settled[j]);
            record(second, i, js);
          });
    });
    par::set_threads(0);
    EXPECT_TRUE(settled_in_time) << threads << " threads";
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(first[i], first_apart[i]) << "particle " << i << ", " << threads << " threads";
      ASSERT_EQ(second[i], second_apart[i]) << "particle " << i << ", " << threads << " threads";
      ASSERT_EQ(settled[i], i < m ? 1 : 0) << "particle " << i;
      if (i < m) ASSERT_EQ(seen_when_settled[i], first[i].size()) << "particle " << i << " settled before its last term";
    }
  }
}

namespace {

// Rates with pairs searched anew equal those with stored lists, with viscosity and pressure,
// starting from h = h0: on all particles and on the first `active` (block timesteps; the second
// evaluation starts from the first's h and rho, inactive particles' included), with and without the
// force correction and in the consistent form (whose momentum is not exact: the conservation check
// is for the other two). With adaptive h bit for bit: the smoothing lengths are solved from the same
// candidates in the same order, both sources give each pair to the same particle (the first in
// cell order whose support holds it) on the same tile schedule, and list each particle's partners
// in cell order, so every sum adds the same terms in the same order. With one h to round-off: the
// stored lists' schedule writes forward only, so the terms arrive in another order.
template <int D>
void check_rates_equal_stored(Particles<D> p0, double h0, Smoothing smoothing, test::Form form, std::size_t active) {
  std::fill(p0.h.begin(), p0.h.end(), h0);
  PhysicsParams phys;
  phys.nu = 0.01;
  phys.gm = 0.0;
  phys.eos = EquationOfState::Isothermal;
  phys.sound_speed = 0.3;
  phys = test::with_form(phys, form);
  PhaseTimers timers;
  Particles<D> stored_p = p0, scanned_p = p0;
  RateEvaluator<D> stored(KernelType::Cubic, h0, phys, timers, smoothing, 50);
  RateEvaluator<D> scanned(KernelType::Cubic, h0, phys, timers, smoothing, 50);
  scanned.set_pair_storage(PairStorage::Rescan);
  for (int pass = 0; pass < 2; ++pass) {
    stored.evaluate(stored_p, pass == 0 ? stored_p.size() : active);
    scanned.evaluate(scanned_p, pass == 0 ? scanned_p.size() : active);
  }
  EXPECT_EQ(scanned.pair_interactions(), stored.pair_interactions());
  double acc_scale = 0, du_scale = 0;
  for (std::size_t i = 0; i < p0.size(); ++i) {
    acc_scale = std::max(acc_scale, norm(stored_p.acc[i]));
    du_scale = std::max(du_scale, std::abs(stored_p.du_dt[i]));
  }
  if (smoothing == Smoothing::Adaptive) {
    for (std::size_t i = 0; i < p0.size(); ++i) {
      ASSERT_EQ(scanned_p.h[i], stored_p.h[i]) << "particle " << i;
      ASSERT_EQ(scanned_p.rho[i], stored_p.rho[i]) << "particle " << i;
      ASSERT_EQ(scanned_p.acc[i], stored_p.acc[i]) << "particle " << i;
      ASSERT_EQ(scanned_p.du_dt[i], stored_p.du_dt[i]) << "particle " << i;
      ASSERT_EQ(scanned_p.stress[i].c, stored_p.stress[i].c) << "particle " << i;
    }
  }
  for (std::size_t i = 0; i < p0.size(); ++i) {
    ASSERT_EQ(scanned_p.h[i], stored_p.h[i]) << "particle " << i;
    ASSERT_NEAR(scanned_p.rho[i], stored_p.rho[i], 1e-13 * stored_p.rho[i]) << "particle " << i;
    ASSERT_LT(norm(scanned_p.acc[i] - stored_p.acc[i]), 1e-12 * acc_scale) << "particle " << i;
    ASSERT_NEAR(scanned_p.du_dt[i], stored_p.du_dt[i], 1e-12 * du_scale) << "particle " << i;
    for (std::size_t c = 0; c < stored_p.stress[i].c.size(); ++c)
      ASSERT_NEAR(scanned_p.stress[i].c[c], stored_p.stress[i].c[c], 1e-12 * (std::abs(stored_p.stress[i].c[c]) + 1e-3)) << "particle " << i;
  }
  if constexpr (D == 2)  // the conservation check of test_helpers.hpp is written for 2D
    if (active == p0.size() && !test::is_consistent(form))
      test::expect_momentum_and_energy_conserved(scanned_p, "rescanned pairs");
}

void check_rates_equal_stored(Smoothing smoothing, test::Form form, std::size_t active) {
  check_rates_equal_stored(test::sheared_lattice(), 0.025, smoothing, form, active);
}

}  // namespace

TEST(PairScan, RatesEqualStoredListsConstantH) { check_rates_equal_stored(Smoothing::Constant, test::Form::Consistent, 1600); }
TEST(PairScan, RatesEqualStoredListsConstantHConservative) {
  check_rates_equal_stored(Smoothing::Constant, test::Form::Conservative, 1600);
}
TEST(PairScan, RatesEqualStoredListsAdaptiveH) { check_rates_equal_stored(Smoothing::Adaptive, test::Form::Consistent, 1600); }
TEST(PairScan, RatesEqualStoredListsAdaptiveHConservative) {
  check_rates_equal_stored(Smoothing::Adaptive, test::Form::Conservative, 1600);
}
TEST(PairScan, RatesEqualStoredListsWithForceCorrection) {
  check_rates_equal_stored(Smoothing::Adaptive, test::Form::ForceCorrected, 1600);
}
TEST(PairScan, RatesEqualStoredListsWithMixedCorrection) {
  check_rates_equal_stored(Smoothing::Adaptive, test::Form::ConsistentMixed, 1600);
}
TEST(PairScan, RatesEqualStoredListsForActiveParticles) {
  check_rates_equal_stored(Smoothing::Adaptive, test::Form::Consistent, 500);
  check_rates_equal_stored(Smoothing::Adaptive, test::Form::ConsistentMixed, 500);
  check_rates_equal_stored(Smoothing::Constant, test::Form::Consistent, 700);
  check_rates_equal_stored(Smoothing::Adaptive, test::Form::Conservative, 500);
}

// The same in 3D (random particles, half of them clustered, so h varies; with pressure):
// rescanned pairs give the rates of stored lists.
TEST(PairScan, RatesEqualStoredLists3D) {
  for (test::Form form : {test::Form::Consistent, test::Form::ConsistentMixed, test::Form::Conservative})
    check_rates_equal_stored(test::random_particles<3>(2000, 54, true), 0.05, Smoothing::Adaptive, form, 2000);
}
