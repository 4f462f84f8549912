// Partial evaluations (block timesteps) on the particles the active ones involve
// (neighbours/involved_particles.hpp, RateEvaluator::evaluate_involved): the selection holds every
// particle a brute-force search says may interact, and the evaluation on it gives the bits of the
// evaluation over all particles.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <random>

#include "evaluate/rate_evaluator.hpp"
#include "neighbours/involved_particles.hpp"
#include "test_helpers.hpp"

namespace sphdisk {
namespace {

// Every inactive j within max(radius[i], 2 h_j) of an active i is a member; the members are the
// active ones first, then increasing indices; and the selection is not much larger than needed
// (a selection of everyone would make the evaluation slow, not wrong: this bounds it).
template <int D>
void check_involved(std::size_t n, std::size_t active, unsigned seed) {
  auto p = test::random_particles<D>(n, seed, true);
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> h(n), radius(active);
  for (double& x : h) x = 0.005 + 0.03 * u(g) * u(g);
  for (double& r : radius) r = 0.01 + 0.05 * u(g) * u(g);
  std::vector<std::uint32_t> members;
  involved_particles(p.pos, h, active, radius, members);
  ASSERT_GE(members.size(), active);
  for (std::size_t i = 0; i < active; ++i) ASSERT_EQ(members[i], i);
  ASSERT_TRUE(std::is_sorted(members.begin(), members.end()));
  ASSERT_TRUE(std::adjacent_find(members.begin(), members.end()) == members.end());
  std::size_t needed = 0;
  for (std::size_t j = active; j < n; ++j) {
    bool interacts = false;
    for (std::size_t i = 0; i < active && !interacts; ++i) {
      const double reach = std::max(radius[i], 2.0 * h[j]);
      interacts = norm2(p.pos[i] - p.pos[j]) < reach * reach;
    }
    if (!interacts) continue;
    ++needed;
    ASSERT_TRUE(std::binary_search(members.begin(), members.end(), static_cast<std::uint32_t>(j)))
        << "particle " << j << " interacts with an active one but was left out";
  }
  EXPECT_GT(needed, 0u);
  EXPECT_LT(members.size() - active, 4 * needed + 16) << "needed " << needed;
  EXPECT_LT(members.size(), n);
}

TEST(InvolvedParticles, HoldEveryInteractingParticle2D) {
  check_involved<2>(6000, 40, 3);
  check_involved<2>(6000, 600, 4);
}
TEST(InvolvedParticles, HoldEveryInteractingParticle3D) { check_involved<3>(6000, 60, 5); }

TEST(InvolvedParticles, NoneActiveAndUnboundedReach) {
  auto p = test::random_particles<2>(500, 7, false);
  std::vector<double> h(500, 0.01);
  std::vector<std::uint32_t> members{9, 9};
  involved_particles(p.pos, h, 0, {}, members);
  EXPECT_TRUE(members.empty());
  std::vector<double> radius{0.01, std::numeric_limits<double>::infinity()};
  involved_particles(p.pos, h, 2, radius, members);
  EXPECT_EQ(members.size(), 500u);  // an unbounded radius involves everyone
}

template <int D>
void expect_same_bits(Particles<D> a, const Particles<D>& b) {
  ASSERT_EQ(a.size(), b.size());
  a.for_each_field_with(b, [](const FieldInfo& info, const auto& x, const auto& y) {
    ASSERT_EQ(x.size(), y.size()) << info.name;
    EXPECT_EQ(0, std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0]))) << "field " << info.name << " differs";
  });
}

// A full evaluation, the particles moved, then partial evaluations of the first `active` particles
// on the involved particles and over all of them: every field of every particle the same bits.
// shrink: the active particles' h scaled by it (with no history) before the partial evaluations,
// so that their solves must search beyond the involved particles first (widenings).
// scattered: the active particles spread over the whole set (else the ones nearest a corner), so
// that widened searches involve more than half of all and the evaluation is made over all after
// all. involved: the evaluations expected on the involved particles.
template <int D>
void check_partial_evaluations(Smoothing smoothing, double h0, double neighbours, std::size_t active, double shrink = 1.0,
                               bool scattered = false, std::size_t involved = 2) {
  auto p = test::random_particles<D>(8000, 11, false);
  if (!scattered) {  // the active particles (the first ones) nearest a corner, as a time bin is a region of a disc
    std::vector<std::uint32_t> order(p.size());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) { return norm2(p.pos[x]) < norm2(p.pos[y]); });
    p.gather(order);
  }
  std::fill(p.h.begin(), p.h.end(), h0);
  PhaseTimers timers;
  {
    RateEvaluator<D> full(KernelType::Cubic, h0, test::viscous_no_gravity(0.01), timers, smoothing, neighbours);
    full.evaluate(p);
  }
  for (std::size_t i = 0; i < p.size(); ++i) p.pos[i] += p.vel[i] * 1e-3;
  for (std::size_t i = 0; i < active && shrink != 1.0; ++i) {
    p.h[i] *= shrink;
    p.h_prev[i] = p.h_prev2[i] = 0.0;
  }
  auto on_involved = p, on_all = p;
  RateEvaluator<D> a(KernelType::Cubic, h0, test::viscous_no_gravity(0.01), timers, smoothing, neighbours);
  RateEvaluator<D> b(KernelType::Cubic, h0, test::viscous_no_gravity(0.01), timers, smoothing, neighbours);
  b.set_partial_on_involved(false);
  for (int round = 0; round < 2; ++round) {
    a.evaluate(on_involved, active);
    b.evaluate(on_all, active);
    for (auto* q : {&on_involved, &on_all})
      for (std::size_t i = 0; i < q->size(); ++i) q->pos[i] += q->vel[i] * 1e-3;
  }
  EXPECT_EQ(a.involved_evaluations(), involved) << "the partial evaluations did not take the involved particles as expected";
  EXPECT_EQ(b.involved_evaluations(), 0u);
  if (shrink != 1.0) EXPECT_GT(a.involved_widenings(), 0u);
  EXPECT_EQ(a.particle_updates(), b.particle_updates());
  EXPECT_EQ(a.pair_interactions(), b.pair_interactions());
  expect_same_bits(on_involved, on_all);
}

TEST(PartialEvaluation, InvolvedParticlesGiveTheBitsOfAllAdaptive2D) {
  check_partial_evaluations<2>(Smoothing::Adaptive, 0.02, 50, 40);
  check_partial_evaluations<2>(Smoothing::Adaptive, 0.02, 50, 150);
  // More active than kInvolvedActive (2%): over all particles.
  check_partial_evaluations<2>(Smoothing::Adaptive, 0.02, 50, 1200, 1.0, false, 0);
}
TEST(PartialEvaluation, InvolvedParticlesGiveTheBitsOfAllAdaptive3D) {
  check_partial_evaluations<3>(Smoothing::Adaptive, 0.08, 57, 150);
}
TEST(PartialEvaluation, InvolvedParticlesGiveTheBitsOfAllConstantH) {
  check_partial_evaluations<2>(Smoothing::Constant, 0.015, 50, 150);
}
TEST(PartialEvaluation, SolvesBeyondTheInvolvedParticlesAreRepeatedWithMore) {
  check_partial_evaluations<2>(Smoothing::Adaptive, 0.02, 50, 100, 0.2);
}
// Widened until the involved particles are too many, the evaluations are made over all particles.
TEST(PartialEvaluation, WideningsBeyondHalfTheParticlesFallBackToAll) {
  check_partial_evaluations<2>(Smoothing::Adaptive, 0.02, 50, 60, 0.01, true, 0);
}

}  // namespace
}  // namespace sphdisk
