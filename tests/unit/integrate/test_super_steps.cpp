// Runge-Kutta-Legendre super-steps (integrate/super_steps.hpp) on the 1D heat equation, whose
// discrete modes decay at known rates: stages as few as reach the step, the coefficients of the
// paper's recursion (sum rules), stability far beyond the explicit limit where too few stages blow
// up, second-order accuracy, the plan with the fewest evaluations, and per-component steps.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "integrate/super_steps.hpp"

namespace sphdisk {
namespace {

TEST(SuperSteps, FewestStagesThatReachTheStep) {
  EXPECT_EQ(rkl2_stages(0.0), 1);
  EXPECT_EQ(rkl2_stages(1.0), 1);
  for (double ratio : {1.01, 2.5, 2.51, 4.5, 7.0, 10.0, 27.0, 100.0, 1234.5}) {
    const int s = rkl2_stages(ratio);
    EXPECT_GE(rkl2_reach(s), ratio) << ratio;
    EXPECT_TRUE(s == 2 || rkl2_reach(s - 1) < ratio) << ratio;
  }
  EXPECT_EQ(rkl2_stages(2.5), 3);   // (9 + 3 - 2) / 4
  EXPECT_EQ(rkl2_stages(2.51), 4);  // (16 + 4 - 2) / 4 = 4.5
}

// Each stage is consistent (its weights of Y sum to one) and the step is first order by itself:
// for dy/dt = 1 the stages are Y_j = c_j tau with c_s = 1 (Meyer et al. 2014: c_j = (j^2 + j - 2) /
// (s^2 + s - 2)).
TEST(SuperSteps, StagesAreConsistent) {
  for (int s : {2, 3, 5, 8, 16}) {
    double y_prev = 0, y = rkl2_stage(s, 1).mu_tilde;
    for (int j = 2; j <= s; ++j) {
      const Rkl2Stage c = rkl2_stage(s, j);
      EXPECT_NEAR(c.mu + c.nu + c.start(), 1.0, 1e-15);
      const double next = c.mu * y + c.nu * y_prev + c.mu_tilde + c.gamma_tilde;
      y_prev = y;
      y = next;
      EXPECT_NEAR(y, (j * j + j - 2.0) / (s * s + s - 2.0), 1e-13) << s << " " << j;
    }
  }
}

// The periodic 1D heat equation dy/dt = (y_(i+1) - 2 y_i + y_(i-1)) / dx^2 (explicit limit dx^2 / 2)
// with a smooth mode and the fastest (sawtooth) mode; each decays by exp(-lambda t) exactly.
struct Heat {
  std::size_t n = 64;
  double dx = 1.0 / 64;
  std::vector<double> y, l;
  Heat() : y(n), l(n) {}
  void rate() {
    for (std::size_t i = 0; i < n; ++i) l[i] = (y[(i + 1) % n] - 2.0 * y[i] + y[(i + n - 1) % n]) / (dx * dx);
  }
  double explicit_limit() const { return 0.5 * dx * dx; }
  static double decay(int k, double dx) {  // eigenvalue of the mode cos(2 pi k x)
    return 4.0 / (dx * dx) * std::pow(std::sin(std::numbers::pi * k * dx), 2);
  }
};

struct HeatResult {
  double smooth_error;  // |amplitude of cos(2 pi x) - its exact value|
  double sawtooth;      // amplitude left of the fastest mode (started at 0.5; exact: ~0)
};

// Advances mode 1 plus the sawtooth to t_end with steps of `ratio` explicit limits and s stages (0:
// as many as the step takes).
HeatResult heat_after(double ratio, int stages, double t_end) {
  Heat h;
  const double pi2 = 2 * std::numbers::pi;
  for (std::size_t i = 0; i < h.n; ++i) h.y[i] = std::cos(pi2 * i * h.dx) + 0.5 * (i % 2 ? -1.0 : 1.0);
  const double tau = ratio * h.explicit_limit();
  const int steps = static_cast<int>(std::lround(t_end / tau));
  Rkl2Part<double> part;
  std::vector<double> start;  // Y_0 of each step
  part.bind(h.y, h.l, start, h.n);
  const auto each = [](std::size_t n, auto&& f) {
    for (std::size_t i = 0; i < n; ++i) f(i);
  };
  const SuperStepPlan plan{true, stages > 0 ? stages : rkl2_stages(ratio)};
  for (int k = 0; k < steps; ++k) {
    h.rate();
    start = h.y;
    super_step(h.n, plan.evaluations, [plan](std::size_t) { return plan; }, [tau](std::size_t) { return tau; },
               [&](std::size_t m) {
                 EXPECT_EQ(m, h.n);
                 h.rate();
               },
               each, part);
  }
  double smooth = 0, saw = 0;
  for (std::size_t i = 0; i < h.n; ++i) {
    smooth += 2.0 * std::cos(pi2 * i * h.dx) * h.y[i] / h.n;
    saw += (i % 2 ? -1.0 : 1.0) * h.y[i] / h.n;
  }
  return {std::abs(smooth - std::exp(-Heat::decay(1, h.dx) * steps * tau)), saw};
}

TEST(SuperSteps, StableFarBeyondTheExplicitLimit) {
  // 40 explicit limits per step with 13 stages (reach 45): the stiffest mode does not grow, and the
  // smooth one follows its exact decay.
  const HeatResult ok = heat_after(40.0, 0, 0.02);
  EXPECT_LT(ok.smooth_error, 2e-3);
  EXPECT_LT(std::abs(ok.sawtooth), 0.5);
  // Too few stages for the step (reach 27 < 40): the stiffest mode grows.
  EXPECT_GT(std::abs(heat_after(40.0, 10, 0.02).sawtooth), 1.0);
}

TEST(SuperSteps, SecondOrderInTheStep) {
  // The smooth mode's error at a fixed time falls ~4x when the step halves.
  const double coarse = heat_after(64.0, 0, 0.04).smooth_error, fine = heat_after(32.0, 0, 0.04).smooth_error;
  EXPECT_GT(coarse / fine, 3.0) << coarse << " " << fine;
  EXPECT_LT(coarse / fine, 5.5) << coarse << " " << fine;
}

// Forward-Euler substeps where they need no more evaluations than RKL2's stages (up to 4 limits).
TEST(SuperSteps, PlanTakesTheFewestEvaluations) {
  const auto check = [](double ratio, bool legendre, int evaluations) {
    const SuperStepPlan plan = super_step_plan(ratio);
    EXPECT_EQ(plan.legendre, legendre) << ratio;
    EXPECT_EQ(plan.evaluations, evaluations) << ratio;
  };
  check(0.0, false, 1);
  check(1.0, false, 1);
  check(1.5, false, 2);
  check(3.0, false, 3);   // RKL2: 4 stages
  check(4.0, false, 4);   // RKL2: 4 stages as well
  check(4.4, true, 4);    // substeps: 5
  check(40.0, true, 13);  // substeps: 40
}

// A constant rate is integrated exactly over each component's own step with its own plan; the
// components are ordered by evaluations, most first, and each evaluation after the first covers only
// those that still need it.
TEST(SuperSteps, ComponentsTakeTheirOwnStepsAndPlans) {
  const std::vector<SuperStepPlan> plans = {{true, 7}, {false, 3}, {true, 2}, {false, 1}};
  std::vector<double> y = {1.0, 2.0, 3.0, 4.0}, l(4);
  const std::vector<double> rate = {-2.0, 4.0, 0.25, 8.0};
  Rkl2Part<double> part;
  const std::vector<double> start = y;
  part.bind(y, l, start, 4);
  const auto each = [](std::size_t n, auto&& f) {
    for (std::size_t i = 0; i < n; ++i) f(i);
  };
  std::vector<std::size_t> covered;
  l = rate;
  super_step(4, 7, [&](std::size_t i) { return plans[i]; }, [](std::size_t i) { return 0.5 * (i + 1.0); },
             [&](std::size_t m) {
               covered.push_back(m);
               for (std::size_t i = 0; i < m; ++i) l[i] = rate[i];
             },
             each, part);
  EXPECT_EQ(covered, (std::vector<std::size_t>{3, 2, 1, 1, 1, 1}));
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(y[i], (i + 1.0) + rate[i] * 0.5 * (i + 1.0), 1e-14) << i;
}

// A component with fewer evaluations is seen by the others at its start value until all are done:
// on two coupled components (dy/dt = -(y_0 - y_1), -(y_1 - y_0)) the second, done after one
// forward-Euler step, ends at 0 + 0.5 (1 - 0); the first relaxes towards the second's start value 0
// (exactly: exp(-0.5)).
TEST(SuperSteps, FinishedComponentsAreSeenAtTheirStart) {
  std::vector<double> y = {1.0, 0.0}, l(2);
  Rkl2Part<double> part;
  const std::vector<double> start = y;
  part.bind(y, l, start, 2);
  std::vector<double> seen;  // y_1 as the later stages see it
  const auto rate = [&](std::size_t m) {
    const double d = y[0] - y[1];
    if (m > 0) l[0] = -d;
    if (m > 1) l[1] = d;
  };
  const auto each = [](std::size_t n, auto&& f) {
    for (std::size_t i = 0; i < n; ++i) f(i);
  };
  rate(2);
  const std::vector<SuperStepPlan> plans = {{true, 5}, {false, 1}};
  super_step(2, 5, [&](std::size_t i) { return plans[i]; }, [](std::size_t) { return 0.5; },
             [&](std::size_t m) {
               EXPECT_EQ(m, 1u);
               seen.push_back(y[1]);
               rate(m);
             },
             each, part);
  EXPECT_EQ(seen, std::vector<double>(4, 0.0));
  EXPECT_DOUBLE_EQ(y[1], 0.5);
  EXPECT_NEAR(y[0], std::exp(-0.5), 1e-2);  // (RKL2 alone gives 0.6136 here: its second-order error)
}

}  // namespace
}  // namespace sphdisk
