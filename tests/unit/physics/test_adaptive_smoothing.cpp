// Adaptive smoothing lengths (physics/smoothing_length.hpp) and the pairs they interact in
// (neighbours/pair_lists.hpp: |x_i - x_j| < 2 max(h_i, h_j), each pair once), against brute force.
#include <gtest/gtest.h>

#include <map>

#include <algorithm>
#include <random>

#include "evaluate/rate_evaluator.hpp"
#include "neighbours/pair_lists.hpp"
#include "parallel/loops.hpp"
#include "physics/smoothing_length.hpp"
#include "physics/viscous_stress.hpp"
#include "test_helpers.hpp"

using namespace sphdisk;

namespace {

template <int D>
std::vector<double> random_smoothing_lengths(std::size_t n, double lo, double hi, unsigned seed) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> h(n);
  for (auto& x : h) x = u(g);
  return h;
}

// The half lists built from gather lists hold every pair with |x_i - x_j| < 2 max(h_i, h_j) exactly
// once, also pairs that only the wider support of one particle covers ("scatter" pairs).
template <int D>
void check_interaction_pairs(const Particles<D>& p, const std::vector<double>& h, int tile_cells) {
  std::vector<double> radius(h.size());
  for (std::size_t i = 0; i < h.size(); ++i) radius[i] = 2.0 * h[i];
  const auto grid = build_cell_grid(p.pos, p.id, 0.5 * *std::min_element(radius.begin(), radius.end()));
  NeighbourLists gather;
  build_neighbour_lists(grid, p.pos, radius, gather);
  PairLists pairs;
  build_tile_order(grid, tile_cells, p.size(), pairs, TileWrites::AllNeighbours);
  build_half_lists_from_gather(gather, p.pos, h, pairs);
  std::vector<std::vector<std::uint32_t>> got(p.size());
  for_each_pair(pairs, [&](std::uint32_t i, std::uint32_t j, std::size_t) {
    got[i].push_back(j);  // i is written by one task at a time, j by one task at a time
    got[j].push_back(i);
  });
  std::size_t scatter_only = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    std::vector<std::uint32_t> brute;
    for (std::size_t j = 0; j < p.size(); ++j) {
      const double r = norm(p.pos[j] - p.pos[i]);
      if (j != i && r < 2.0 * std::max(h[i], h[j])) brute.push_back(static_cast<std::uint32_t>(j));
      if (j != i && r < 2.0 * h[j] && r >= 2.0 * h[i]) ++scatter_only;
    }
    std::sort(got[i].begin(), got[i].end());
    ASSERT_EQ(got[i], brute) << "particle " << i;
  }
  EXPECT_GT(scatter_only, p.size());  // the test exercises the scatter half
  // Near lists hold the pairs of equal or adjacent tiles, far lists the others (the schedule's
  // colouring relies on it; particles with supports below a tile length skip the comparison).
  for (const auto& [lists, near] : {std::pair{&pairs.near, true}, std::pair{&pairs.far, false}})
    for (std::size_t k = 0; k < lists->size(); ++k)  // list k is particle order[k]'s
      for (const std::uint32_t* it = lists->begin(k); it != lists->end(k); ++it) {
        const std::size_t i = pairs.order[k];
        ASSERT_EQ(tiles_adjacent<D>(pairs.tile.data() + D * i, pairs.tile.data() + D * *it), near) << i << " " << *it;
      }
}

// Evaluates the rates with adaptive smoothing, starting every h from h0.
template <int D>
void evaluate_adaptive(Particles<D>& p, double h0, double neighbours, PhysicsParams phys,
                       KernelType kernel = KernelType::Cubic) {
  std::fill(p.h.begin(), p.h.end(), h0);
  PhaseTimers timers;
  RateEvaluator<D> rates(kernel, h0, phys, timers, Smoothing::Adaptive, neighbours);
  rates.evaluate(p);
}

}  // namespace

// Tiles of 16 cells span every support here; tiles of 3 leave many pairs far.
TEST(InteractionPairs, EqualBruteForceWithVariableH2D) {
  const auto p = test::random_particles<2>(2000, 5, true);
  for (int tile_cells : {16, 3}) check_interaction_pairs(p, random_smoothing_lengths<2>(p.size(), 0.005, 0.04, 6), tile_cells);
}

TEST(InteractionPairs, EqualBruteForceWithVariableH3D) {
  const auto p = test::random_particles<3>(2000, 7, true);
  for (int tile_cells : {8, 2}) check_interaction_pairs(p, random_smoothing_lengths<3>(p.size(), 0.02, 0.08, 8), tile_cells);
}

// Each solved h_i satisfies h_i = eta (m_i / rho_i)^(1/D) with rho_i summed by brute force, also
// for particles far from the start value (clustered set, one h0 for all).
// unequal: masses spread over a factor 3 (the solve then gathers them; equal ones it fills in).
template <int D>
void check_solved_smoothing_lengths(double neighbours, double h0, bool unequal = false) {
  auto p = test::random_particles<D>(1500, 9, true);
  if (unequal)
    for (std::size_t i = 0; i < p.size(); ++i) p.mass[i] *= 0.5 + static_cast<double>(i % 7) / 4.0;
  ASSERT_EQ(uniform_mass_of(p) > 0, !unequal);
  evaluate_adaptive(p, h0, neighbours, test::viscous_no_gravity(0.0));
  const double eta = eta_for_neighbours<D>(neighbours);
  double worst = 0, h_min = 1e300, h_max = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const KernelAt<CubicSpline, D> kern(p.h[i]);
    double rho = 0;
    for (std::size_t j = 0; j < p.size(); ++j) rho += p.mass[j] * kern.W(norm(p.pos[i] - p.pos[j]));
    worst = std::max(worst, std::abs(p.h[i] / (eta * std::pow(p.mass[i] / rho, 1.0 / D)) - 1.0));
    worst = std::max(worst, std::abs(p.rho[i] / rho - 1.0));
    h_min = std::min(h_min, p.h[i]);
    h_max = std::max(h_max, p.h[i]);
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_GT(h_max / h_min, 3.0);  // the set really needs different h
}

TEST(SmoothingLength, SolvesTheDensityEquation2D) { check_solved_smoothing_lengths<2>(50, 0.02); }
TEST(SmoothingLength, SolvesTheDensityEquation3D) { check_solved_smoothing_lengths<3>(57, 0.1); }
TEST(SmoothingLength, SolvesTheDensityEquationWithUnequalMasses2D) { check_solved_smoothing_lengths<2>(50, 0.02, true); }

// Equal masses factored out of the sums (m sum_j w_j) give the solution of the gathered ones
// (sum_j m_j w_j) to round-off: the two differ only in where m multiplies. Both paths are checked
// against brute-force sums elsewhere; this keeps them in step. rho is compared to 1e-13 relative
// (a few ulps of ~100 summands); h to 1e-13 as well, since the same Newton steps follow from
// densities this close (a step that lands within round-off of the stopping test could differ, and
// would show here).
TEST(SmoothingLength, FactoredEqualMassesGiveTheGatheredResult) {
  const auto p = test::random_particles<2>(600, 4, true);
  const double m = uniform_mass_of(p);
  ASSERT_GT(m, 0.0);
  const double eta = eta_for_neighbours<2>(50);
  for (std::size_t i = 0; i < p.size(); i += 7) {
    std::vector<std::uint32_t> cand;
    for (std::uint32_t j = 0; j < p.size(); ++j)
      if (j != i && norm(p.pos[i] - p.pos[j]) < 0.2) cand.push_back(j);
    const auto filled = smoothing_length_at<CubicSpline, 2>(i, p, cand, {}, 0.03, eta, 0.1, m);
    const auto gathered = smoothing_length_at<CubicSpline, 2>(i, p, cand, {}, 0.03, eta, 0.1, 0.0);
    ASSERT_NEAR(filled.h, gathered.h, 1e-13 * gathered.h) << i;
    ASSERT_NEAR(filled.rho, gathered.rho, 1e-13 * gathered.rho) << i;
    ASSERT_EQ(filled.sums, gathered.sums) << i;
    ASSERT_EQ(filled.beyond_candidates, gathered.beyond_candidates) << i;
  }
}

// On a lattice the summation density is exact to ~1% for h >~ 1.3 dx, so h solves to eta dx.
TEST(SmoothingLength, EtaTimesSpacingOnALattice) {
  const int n = 40;
  const double dx = 1.0 / n;
  for (double neighbours : {30.0, 50.0, 100.0}) {
    auto p = test::square_lattice(n, dx);
    evaluate_adaptive(p, 3.0 * dx, neighbours, test::viscous_no_gravity(0.0));
    const auto inner = test::interior(p, 0.5, 0.25);
    ASSERT_GT(inner.size(), 200u);
    const double expected = eta_for_neighbours<2>(neighbours) * dx;
    for (std::size_t i : inner) ASSERT_NEAR(p.h[i], expected, 0.01 * expected) << "N_ngb " << neighbours;
  }
}

// A particle far from all others widens its search until it finds its neighbours; a set too small
// to fill any kernel keeps every particle as a neighbour instead of failing.
TEST(SmoothingLength, OutliersAndTinySets) {
  auto p = test::random_particles<2>(500, 12, false);
  p.pos[17] = Vec<2>{{40.0, -25.0}};
  evaluate_adaptive(p, 0.05, 40, test::viscous_no_gravity(0.01));
  EXPECT_GT(p.h[17], 10.0);
  for (std::size_t i = 0; i < p.size(); ++i) ASSERT_TRUE(std::isfinite(p.acc[i][0]) && std::isfinite(p.h[i]));

  auto tiny = test::random_particles<2>(5, 13, false);
  evaluate_adaptive(tiny, 0.01, 60, test::viscous_no_gravity(0.01));
  for (std::size_t i = 0; i < tiny.size(); ++i) ASSERT_TRUE(std::isfinite(tiny.acc[i][0]) && tiny.h[i] > 0.01);
}

// Pair antisymmetry survives variable h (averaged kernel gradient on symmetric lists): momentum
// and kinetic + internal energy are conserved to round-off; the corrected gradient stays exact for
// linear fields and a rigid rotation has no shear.
TEST(SmoothingLength, ConservationAndLinearExactnessWithVariableH) {
  const double A[2][2] = {{0.3, -1.1}, {0.7, 0.2}};
  auto p = test::random_particles<2>(3000, 14, true);
  for (auto& x : p.pos) x += Vec<2>{{2.0, 2.0}};
  PhysicsParams phys = test::viscous_no_gravity(0.01);
  phys.nu_bulk = 0.003;
  phys.eos = EquationOfState::Isothermal;
  phys.sound_speed = 0.3;
  phys.evolve_energy = true;
  for (bool force_correction : {true, false}) {  // the rest of the test uses the last set of rates
    // (the conservative form of eq. 6, whose conservation is exact: physics_params.hpp)
    phys = test::with_form(phys, force_correction ? test::Form::ForceCorrected : test::Form::Conservative);
    evaluate_adaptive(p, 0.02, 50, phys, KernelType::WendlandC2);
    test::expect_momentum_and_energy_conserved(p, force_correction ? "adaptive h, force correction" : "adaptive h");
  }

  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec<2> x = p.pos[i];
    p.vel[i] = Vec<2>{{A[0][0] * x[0] + A[0][1] * x[1] + 5.0, A[1][0] * x[0] + A[1][1] * x[1] - 2.0}};
  }
  PhaseTimers timers;
  RateEvaluator<2> rates(KernelType::Cubic, 0.02, test::viscous_no_gravity(1.0), timers, Smoothing::Adaptive, 50);
  rates.evaluate(p);
  double worst = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Mat<2> G = corrected_gradient(rates.gradient_sums()[i]);
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) worst = std::max(worst, std::abs(G(a, b) - A[a][b]));
  }
  EXPECT_LT(worst, 1e-5);

  const double omega = 2.5;
  for (std::size_t i = 0; i < p.size(); ++i) p.vel[i] = Vec<2>{{-omega * p.pos[i][1], omega * p.pos[i][0]}};
  rates.evaluate(p);
  double worst_stress = 0;
  for (const auto& S : p.stress)
    for (double s : S.c) worst_stress = std::max(worst_stress, std::abs(s));
  EXPECT_LT(worst_stress, 1e-6 * omega);
}

// The start values extrapolated from the last solutions (smoothing_length.hpp): none from an
// initial guess or from a single solution, then linear, then quadratic (exact while h is quadratic
// in the evaluation count), limited to 5% of h.
TEST(SmoothingLength, StartValuesFollowTheSolutionHistory) {
  const auto solution = [](int n) { return 0.02 * (1.0 + 0.01 * n + 0.001 * n * n); };
  double h = 0.5, h_prev = 0, h_prev2 = 0;  // an initial guess, no history (a new particle)
  std::vector<double> starts;
  for (int n = 1; n <= 5; ++n) {
    starts.push_back(predicted_smoothing_length(h, h_prev, h_prev2));
    remember_smoothing_length(h, h_prev, h_prev2);
    h = solution(n);  // what the solve returned
  }
  EXPECT_EQ(starts[0], 0.5);
  EXPECT_EQ(starts[1], solution(1));
  EXPECT_NEAR(starts[2], 2.0 * solution(2) - solution(1), 1e-15);
  EXPECT_NEAR(starts[3], solution(4), 1e-15);
  EXPECT_NEAR(starts[4], solution(5), 1e-15);
  EXPECT_EQ(predicted_smoothing_length(1.0, 0.5, 0.25), 1.05);
  EXPECT_EQ(predicted_smoothing_length(1.0, 2.0, 0.0), 1.0 / 1.05);
}

// A solution is a fixed point: particles at rest evaluated again keep their h, each solve taking
// one density sum. (The Newton step from the root is below h's last digit; the solver once took
// that for a step out of its bracket and bisected, leaving h up to 1e-4 off.)
TEST(SmoothingLength, SolutionsAreFixedPoints) {
  auto p = test::random_particles<2>(2000, 22, true);
  std::fill(p.h.begin(), p.h.end(), 0.02);
  PhaseTimers timers;
  RateEvaluator<2> rates(KernelType::Cubic, 0.02, test::viscous_no_gravity(0.0), timers, Smoothing::Adaptive, 50);
  rates.evaluate(p);
  std::vector<double> solved;
  for (int n = 2; n <= 4; ++n) {
    const std::size_t sums = rates.smoothing_length_sums();
    rates.evaluate(p);
    EXPECT_EQ(rates.smoothing_length_sums() - sums, p.size()) << "evaluation " << n;
    if (n == 2) solved = p.h;  // the first solve stopped within ~1e-8 of the root, this one at it
  }
  double worst = 0;
  for (std::size_t i = 0; i < p.size(); ++i) worst = std::max(worst, std::abs(p.h[i] / solved[i] - 1.0));
  EXPECT_LT(worst, 1e-12);
}

// In a homologous expansion (v = a x: every distance, so every solution h, grows as 1 + a t) the
// extrapolated start is the solution to round-off: once the history holds two solutions each solve
// takes one density sum, where the previous h as the start took about two; and the solutions are
// those of solves started from the previous h.
TEST(SmoothingLength, ExtrapolatedStartsSolveInOneSum) {
  auto p = test::random_particles<2>(2000, 21, true);
  std::fill(p.h.begin(), p.h.end(), 0.02);
  const std::vector<Vec<2>> start = p.pos;
  PhaseTimers timers;
  RateEvaluator<2> rates(KernelType::Cubic, 0.02, test::viscous_no_gravity(0.0), timers, Smoothing::Adaptive, 50);
  std::vector<double> sums_per_solve;
  Particles<2> before_last;
  for (int n = 0; n < 7; ++n) {
    for (std::size_t i = 0; i < p.size(); ++i) p.pos[i] = start[i] * (1.0 + 0.004 * n);  // h grows 0.4% per evaluation
    if (n == 6) before_last = p;
    const std::size_t solves = rates.smoothing_length_solves(), sums = rates.smoothing_length_sums();
    rates.evaluate(p);
    ASSERT_EQ(rates.smoothing_length_solves() - solves, p.size());
    sums_per_solve.push_back(static_cast<double>(rates.smoothing_length_sums() - sums) / static_cast<double>(p.size()));
  }
  EXPECT_GT(sums_per_solve[1], 1.5);  // from the previous solution
  for (int n = 3; n < 7; ++n) EXPECT_EQ(sums_per_solve[static_cast<std::size_t>(n)], 1.0) << "evaluation " << n;

  std::fill(before_last.h_prev.begin(), before_last.h_prev.end(), 0.0);  // no history: start from the previous h
  std::fill(before_last.h_prev2.begin(), before_last.h_prev2.end(), 0.0);
  PhaseTimers other_timers;
  RateEvaluator<2> plain(KernelType::Cubic, 0.02, test::viscous_no_gravity(0.0), other_timers, Smoothing::Adaptive, 50);
  plain.evaluate(before_last);
  EXPECT_GT(plain.smoothing_length_sums(), p.size() * 3 / 2);
  double worst = 0;
  for (std::size_t i = 0; i < p.size(); ++i) worst = std::max(worst, std::abs(before_last.h[i] / p.h[i] - 1.0));
  EXPECT_LT(worst, 1e-8);
}

// Same h, lists and rates for any thread count.
TEST(SmoothingLength, SameBitsForAnyThreadCount) {
  std::vector<Particles<2>> results;
  for (int threads : {1, 2, 3}) {
    par::set_threads(threads);
    auto p = test::random_particles<2>(3000, 15, true);
    evaluate_adaptive(p, 0.02, 50, test::viscous_no_gravity(0.01));
    results.push_back(p);
  }
  par::set_threads(0);
  for (std::size_t t = 1; t < results.size(); ++t) {
    EXPECT_EQ(results[t].h, results[0].h);
    for (std::size_t i = 0; i < results[0].size(); ++i) {
      ASSERT_EQ(results[t].acc[i][0], results[0].acc[i][0]);
      ASSERT_EQ(results[t].acc[i][1], results[0].acc[i][1]);
    }
  }
}

// Without stored lists (the mode for runs that would not fit) the evaluator holds no per-particle
// scratch of its pair loops between evaluations but 1/rho and ln rho (the gradient sums alone were
// 64 bytes per particle), and release_rebuilt_memory() (before a reorder) leaves nothing of what it rebuilds;
// the evaluations after it give the same bits as those of an evaluator that kept its memory.
TEST(RateEvaluatorMemory, RescanKeepsNoPairLoopScratchAndReleasesWhatItRebuilds) {
  auto p0 = test::random_particles<2>(2000, 5, false);
  for (auto& hi : p0.h) hi = 0.02;
  PhaseTimers timers;
  RateEvaluator<2> kept(KernelType::Cubic, 0.02, test::viscous_no_gravity(1.0), timers, Smoothing::Adaptive, 50);
  RateEvaluator<2> released(KernelType::Cubic, 0.02, test::viscous_no_gravity(1.0), timers, Smoothing::Adaptive, 50);
  kept.set_pair_storage(PairStorage::Rescan);
  released.set_pair_storage(PairStorage::Rescan);
  Particles<2> p1 = p0, p2 = p0;
  kept.evaluate(p1);
  released.evaluate(p2);
  EXPECT_TRUE(released.gradient_sums().empty());
  std::map<std::string, std::size_t> bytes;
  for (const auto& [part, b] : released.memory()) bytes[part] = b;
  // The force loop's 1/rho, ln rho, rho - m W(0, h), 1/h and sigma/h^D (8 bytes per particle each)
  // and the candidate filter's prefix (4); the gradient sums alone would be 64.
  EXPECT_LT(bytes["per_particle_scratch"], p2.size() * 6 * sizeof(double));
  EXPECT_GT(bytes["cell_grid"], 0u);
  released.release_rebuilt_memory();
  for (const auto& [part, b] : released.memory()) EXPECT_EQ(b, 0u) << part;
  for (int round = 0; round < 2; ++round) {
    kept.evaluate(p1, round == 0 ? p1.size() : 300);
    released.evaluate(p2, round == 0 ? p2.size() : 300);
    for (std::size_t i = 0; i < p1.size(); ++i) {
      ASSERT_EQ(p2.h[i], p1.h[i]) << "particle " << i;
      ASSERT_EQ(p2.acc[i], p1.acc[i]) << "particle " << i;
      ASSERT_EQ(p2.du_dt[i], p1.du_dt[i]) << "particle " << i;
    }
  }
}

// The memory report of the rate evaluator covers what it holds: at least the lists' entries and
// offsets, one pair factor per pair, and one kernel slope per particle.
TEST(RateEvaluatorMemory, CoversTheListsAndFactorsItHolds) {
  auto p = test::random_particles<2>(2000, 5, false);
  for (auto& hi : p.h) hi = 0.02;
  PhaseTimers timers;
  RateEvaluator<2> rates(KernelType::Cubic, 0.02, test::viscous_no_gravity(1.0), timers, Smoothing::Adaptive, 50);
  rates.evaluate(p);
  std::map<std::string, std::size_t> bytes;
  for (const auto& [part, b] : rates.memory()) bytes[part] = b;
  const NeighbourLists& gather = rates.neighbours();
  const PairLists& pairs = rates.pair_lists();
  // The half lists' entries are held apart, or the near ones inside the gather lists (built in tile
  // order, pair_lists.hpp), which are counted as candidate lists.
  const std::size_t apart = pairs.near.within ? pairs.far.total() : pairs.total();
  if (pairs.near.within) EXPECT_EQ(pairs.near.within, &gather);
  EXPECT_GE(bytes["half_lists"], apart * sizeof(std::uint32_t) + 2 * (p.size() + 1) * sizeof(std::size_t));
  EXPECT_GE(bytes["pair_factors"], pairs.total() * sizeof(float));
  EXPECT_GE(bytes["candidate_lists"], gather.total() * sizeof(std::uint32_t) + (p.size() + 1) * sizeof(std::size_t));
  EXPECT_GE(bytes["kernel_slopes"], p.size() * sizeof(KernelSlope));
  EXPECT_GE(p.bytes(), p.size() * (sizeof(Vec<2>) * 3 + sizeof(double) * 4));

  // Rebuilt at about the same size, the lists and factors stay snug (they used to double).
  for (int round = 0; round < 3; ++round) {
    for (std::size_t i = 0; i < p.size(); ++i) p.pos[i][0] *= 1.0 - 1e-3 * static_cast<double>(i % 3);
    rates.evaluate(p);
  }
  for (const auto& [part, b] : rates.memory()) bytes[part] = b;
  const double entries = static_cast<double>(pairs.total());
  EXPECT_LE(static_cast<double>(bytes["pair_factors"]), 1.15 * entries * sizeof(float));
  std::size_t held = pairs.near.index.capacity() + pairs.far.index.capacity();  // joined, or in the builder's blocks
  for (const NeighbourLists* lists : {&pairs.near, &pairs.far})
    for (const auto& block : lists->block_index) held += block.capacity();
  EXPECT_LE(static_cast<double>(held), 1.15 * entries);
}
