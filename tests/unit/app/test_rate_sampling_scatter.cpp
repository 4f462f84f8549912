// The spreading rate's sampling scatter (app/rate_sampling_scatter.hpp) against particle sets
// actually drawn at random from the exact profile and fitted as `sphdisk analyze` fits a run.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "app/rate_sampling_scatter.hpp"
#include "app/ring_analysis.hpp"
#include "problems/ring_setup.hpp"

using namespace sphdisk;

namespace {

constexpr double kTau = 0.09;

// N particles drawn at random (seed `seed`) from the analytic ring at tau = kTau, compared with it;
// `draws` random sets behind the rate's sampling scatter.
RingComparison random_ring(std::size_t n, std::uint64_t seed, int draws) {
  RingSetup s;
  s.solution = RingSolution{1.0, 1.0, 1e-4};
  s.tau_start = kTau;
  s.placement.particles = n;
  s.placement.seed = seed;
  Particles<2> p = make_ring<2>(s);
  for (std::size_t i = 0; i < p.size(); ++i) p.h[i] = 0.01, p.rho[i] = 1.0;  // the SPH Sigma measures are not used
  SnapshotMeta meta;
  meta.tau = kTau;
  meta.viscosity = s.solution.viscosity;
  meta.disc_mass = s.solution.disc_mass;
  return compare_ring(p, meta, 50, 0.05, 2.05, draws);
}

}  // namespace

TEST(RateSamplingScatter, IsTheScatterOfRandomParticleSets) {
  // 16 sets of 10,000 particles: their tau*/tau scatter as the Monte Carlo of annulus counts says.
  // The standard deviation of 16 values is uncertain by ~18%; the bounds are about three times that.
  std::vector<double> rates;
  for (std::uint64_t seed = 1; seed <= 16; ++seed) rates.push_back(random_ring(10000, seed, 0).tau_fit / kTau);
  double mean = 0, var = 0;
  for (double r : rates) mean += r / static_cast<double>(rates.size());
  for (double r : rates) var += (r - mean) * (r - mean) / static_cast<double>(rates.size() - 1);
  const double predicted = random_ring(10000, 1, 200).rate_sampling_sd;
  EXPECT_GT(predicted, 0.01);  // about 0.02 at 10k: a fit that is far from exact at this N
  EXPECT_GT(std::sqrt(var), 0.55 * predicted);
  EXPECT_LT(std::sqrt(var), 1.6 * predicted);
  EXPECT_NEAR(mean, 1.0, 3.0 * predicted / std::sqrt(static_cast<double>(rates.size())));  // the fit is unbiased
}

TEST(RateSamplingScatter, FallsAsOneOverTheSquareRootOfN) {
  const double at_10k = random_ring(10000, 1, 200).rate_sampling_sd;
  const double at_40k = random_ring(40000, 1, 200).rate_sampling_sd;
  EXPECT_GT(at_40k / at_10k, 0.4);
  EXPECT_LT(at_40k / at_10k, 0.62);
  EXPECT_EQ(random_ring(10000, 1, 0).rate_sampling_sd, 0.0);  // no draws, no figure
}

namespace {

// The verdict line of `sphdisk analyze` for a comparison with the given rate and sampling scatter.
std::string verdict_of(double rate, double sd, std::size_t particles) {
  RingComparison c;
  c.tau = kTau;
  c.tau_fit = rate * kTau;
  c.rate_sampling_sd = sd;
  c.particles = particles;
  c.sampling_floor = 0.01;
  c.mass_sigma_l1 = 0.012;
  const std::string table = ring_comparison_table(c);
  const std::size_t at = table.find("verdict:");
  return at == std::string::npos ? "" : table.substr(at, table.find('\n', at) - at);
}

}  // namespace

TEST(RateSamplingScatter, VerdictSaysWhetherTheRateIsOffByMoreThanItsNoise) {
  // 2.1% slow at 10k is NOT within 2%, but one standard deviation of what 10k random particles give.
  EXPECT_EQ(verdict_of(0.979, 0.0208, 10000),
            "verdict: spreading rate NOT within 2% of the analytic one (-0.0210 = 1.0 sd of its sampling scatter: "
            "within the noise of 10000 particles); mass profile within 1.5x its sampling floor");
  // 1.5% fast at 500k is within 2%, and five standard deviations: more than the noise.
  EXPECT_NE(verdict_of(1.015, 0.003, 500000).find("within 2% of the analytic one (+0.0150 = 5.0 sd of its sampling scatter: beyond the noise of 500000 particles)"),
            std::string::npos);
  // No draws behind the scatter: the verdict says nothing about it.
  EXPECT_EQ(verdict_of(1.015, 0.0, 500000).find(" sd "), std::string::npos);
}
