// The stages of a super-step (RateEvaluator::evaluate_again): h and rho stay those of the
// evaluation before, the particles may have been renumbered in between, and the rates are the same
// viscous operator applied to the new velocities.
#include <gtest/gtest.h>

#include <map>

#include "evaluate/rate_evaluator.hpp"
#include "parallel/loops.hpp"
#include "test_helpers.hpp"

using namespace sphdisk;

namespace {

// Each particle's values by ID.
template <int D>
struct Rates {
  typename decltype(Particles<D>::h)::value_type h;  // (the fields' own types: float in the single preset)
  typename decltype(Particles<D>::rho)::value_type rho;
  typename decltype(Particles<D>::du_dt)::value_type du_dt;
  typename decltype(Particles<D>::acc)::value_type acc;
  typename decltype(Particles<D>::stress)::value_type stress;
};
template <int D>
std::map<std::uint64_t, Rates<D>> rates_by_id(const Particles<D>& p, std::size_t count) {
  std::map<std::uint64_t, Rates<D>> r;
  for (std::size_t i = 0; i < count; ++i) r[p.id[i]] = {p.h[i], p.rho[i], p.du_dt[i], p.acc[i], p.stress[i]};
  return r;
}

// An evaluation of all particles, the first half renumbered (reversed), then a stage of the first
// third: their h, rho and rates come out as the evaluation left them, bit for bit (the same h and
// cells, so the same sums in the same order), with no smoothing-length solve; a second stage with
// every velocity doubled (and the stresses the others count with) doubles the accelerations and
// stresses and quadruples the heating exactly (the viscous rates are linear in v, the heating
// quadratic; doubling is exact in floating point).
template <int D>
void check_stages(Particles<D> p, double h0, PairStorage storage, PairDensity density = PairDensity::Summation) {
  std::fill(p.h.begin(), p.h.end(), h0);
  PhysicsParams phys;
  phys.pair_density = density;
  phys.nu = 0.01;
  phys.gm = 0.0;
  phys.evolve_energy = true;
  PhaseTimers timers;
  RateEvaluator<D> rates(KernelType::Cubic, h0, phys, timers, Smoothing::Adaptive, 50);
  rates.set_pair_storage(storage);
  rates.evaluate(p);
  ASSERT_FALSE(p.du_dt.empty());
  const std::size_t n = p.size(), half = n / 2, third = n / 3;
  const auto before = rates_by_id(p, n);

  std::vector<std::uint32_t> moved(half);
  for (std::size_t k = 0; k < half; ++k) moved[k] = static_cast<std::uint32_t>(half - 1 - k);
  p.for_each_field([&](const FieldInfo&, auto& v) { par::permute_prefix(v, moved); });
  const std::size_t solves = rates.smoothing_length_solves();
  rates.evaluate_again(p, third, moved);
  EXPECT_EQ(rates.smoothing_length_solves(), solves);
  for (std::size_t i = 0; i < third; ++i) {
    const Rates<D>& b = before.at(p.id[i]);
    ASSERT_EQ(p.h[i], b.h) << "particle " << p.id[i];
    ASSERT_EQ(p.rho[i], b.rho) << "particle " << p.id[i];
    ASSERT_EQ(p.acc[i], b.acc) << "particle " << p.id[i];
    ASSERT_EQ(p.stress[i].c, b.stress.c) << "particle " << p.id[i];
    ASSERT_EQ(p.du_dt[i], b.du_dt) << "particle " << p.id[i];
  }

  // (The others count with their stresses: doubled with their velocities.)
  for (auto& v : p.vel) v = v * 2.0;
  for (std::size_t i = third; i < n; ++i)
    for (auto& c : p.stress[i].c) c *= 2.0;
  rates.evaluate_again(p, third, {});
  for (std::size_t i = 0; i < third; ++i) {
    const Rates<D>& b = before.at(p.id[i]);
    ASSERT_EQ(p.h[i], b.h) << "particle " << p.id[i];
    ASSERT_EQ(p.acc[i], b.acc * 2.0) << "particle " << p.id[i];
    for (std::size_t c = 0; c < b.stress.c.size(); ++c) ASSERT_EQ(p.stress[i].c[c], 2.0 * b.stress.c[c]) << "particle " << p.id[i];
    ASSERT_EQ(p.du_dt[i], 4.0 * b.du_dt) << "particle " << p.id[i];
  }
  EXPECT_GT(rates.pair_interactions(), 0u);
}

}  // namespace

TEST(SuperStepStages, KeepHAndRhoAndRepeatTheRatesPairsSearchedAnew) {
  check_stages(test::sheared_lattice(), 0.025, PairStorage::Rescan);
  check_stages(test::random_particles<3>(1500, 58, true), 0.05, PairStorage::Rescan);
}

// With the scatter density (kept by the stages, as h and rho are).
TEST(SuperStepStages, KeepHAndRhoAndRepeatTheRatesWithTheScatterDensity) {
  check_stages(test::sheared_lattice(), 0.025, PairStorage::Rescan, PairDensity::Scatter);
  check_stages(test::random_particles<2>(1500, 58, true), 0.05, PairStorage::Stored, PairDensity::Scatter);
}

TEST(SuperStepStages, KeepHAndRhoAndRepeatTheRatesStoredLists) {
  check_stages(test::sheared_lattice(), 0.025, PairStorage::Stored);
  check_stages(test::random_particles<3>(1500, 58, true), 0.05, PairStorage::Stored);
}

namespace {

// The scatter density (PairDensity::Scatter, physics/scatter_density.hpp) of an evaluation with
// adaptive h on clustered particles (h varies several-fold) equals the brute-force sum
// m_i W(0, h_i) + sum_{j != i} m_j W(|x_i - x_j|, h_j) over all particles, differs from the gather
// sum where h varies, and has the same bits for one and two threads.
template <int D>
void check_scatter_density(PairStorage storage) {
  auto evaluate = [&](int threads) {
    par::set_threads(threads);
    Particles<D> p = test::random_particles<D>(1200, 17, true);
    std::fill(p.h.begin(), p.h.end(), 0.05);
    PhysicsParams phys;
    phys.nu = 0.01;
    phys.gm = 0.0;
    phys.pair_density = PairDensity::Scatter;
    PhaseTimers timers;
    RateEvaluator<D> rates(KernelType::Cubic, 0.05, phys, timers, Smoothing::Adaptive, D == 2 ? 30 : 58);
    rates.set_pair_storage(storage);
    p.set_absent_fields(unused_fields(false, false, true, false, false, true));
    rates.evaluate(p);
    par::set_threads(0);
    return p;
  };
  const Particles<D> p = evaluate(2);
  ASSERT_EQ(p.scatter_density.size(), p.size());
  const KernelAt<CubicSpline, D> unit(1.0);
  auto W = [&](double r, double h) { return unit.W(r / h) / std::pow(h, D); };
  double h_min = 1e300, h_max = 0, largest_gap = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    double sum = p.mass[i] * W(0.0, p.h[i]);
    for (std::size_t j = 0; j < p.size(); ++j)
      if (j != i) sum += p.mass[j] * W(std::sqrt(norm2(p.pos[i] - p.pos[j])), p.h[j]);
    ASSERT_NEAR(p.scatter_density[i], sum, 1e-12 * sum) << "particle " << i;
    h_min = std::min(h_min, static_cast<double>(p.h[i])), h_max = std::max(h_max, static_cast<double>(p.h[i]));
    largest_gap = std::max(largest_gap, std::abs(sum / p.rho[i] - 1));
  }
  EXPECT_GT(h_max / h_min, 3.0);
  EXPECT_GT(largest_gap, 0.05);  // not the gather sum
  const Particles<D> one = evaluate(1);
  for (std::size_t i = 0; i < p.size(); ++i) ASSERT_EQ(one.scatter_density[i], p.scatter_density[i]) << "particle " << i;
}

}  // namespace

TEST(ScatterDensity, EqualsBruteForceForPairsSearchedAnew) {
  check_scatter_density<2>(PairStorage::Rescan);
  check_scatter_density<3>(PairStorage::Rescan);
}

TEST(ScatterDensity, EqualsBruteForceForStoredLists) {
  check_scatter_density<2>(PairStorage::Stored);
  check_scatter_density<3>(PairStorage::Stored);
}
