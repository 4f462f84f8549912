#pragma once
// Runge-Kutta-Legendre super-steps of second order (RKL2: Meyer, Balsara & Aslam 2014, MNRAS 438,
// 3182, eqs. 16-19), the super-time-stepping grid codes use for diffusion. s evaluations of the rates
// advance a parabolic (diffusive) system stably over up to (s^2 + s - 2) / 4 explicit limits, where
// s explicit steps go s limits: the viscous stress's limit h^2 / nu, which shrinks as 1/N at a fixed
// neighbour number, then costs ~sqrt(N) evaluations per step instead of ~N (docs/design.md,
// "Viscosity past the h^2/nu limit").
//
// The recursion (tau the step, L the rate, Y_0 the start):
//   Y_1 = Y_0 + mu~_1 tau L(Y_0)
//   Y_j = mu_j Y_(j-1) + nu_j Y_(j-2) + (1 - mu_j - nu_j) Y_0 + mu~_j tau L(Y_(j-1)) + gamma~_j tau L(Y_0)
// with b_0 = b_1 = b_2 = 1/3, b_j = (j^2 + j - 2) / (2 j (j + 1)), a_j = 1 - b_j,
// w_1 = 4 / (s^2 + s - 2), mu~_1 = b_1 w_1, mu_j = (2j - 1)/j b_j / b_(j-1),
// nu_j = -(j - 1)/j b_j / b_(j-2), mu~_j = mu_j w_1, gamma~_j = -a_(j-1) mu~_j; the result is Y_s.
// Steps of up to 4 explicit limits are taken as forward-Euler substeps instead, which need no more
// evaluations there (super_step_plan).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace sphdisk {

// How far s stages reach, in explicit (forward-Euler) limits.
inline double rkl2_reach(int s) { return s <= 1 ? 1.0 : 0.25 * (static_cast<double>(s) * s + s - 2.0); }

// The fewest stages that reach `ratio` explicit limits (1 up to ratio 1).
inline int rkl2_stages(double ratio) {
  if (!(ratio > 1.0)) return 1;
  int s = static_cast<int>(std::ceil(std::sqrt(4.0 * ratio + 2.25) - 0.5));
  while (rkl2_reach(s) < ratio) ++s;  // (round-off in the square root)
  while (s > 2 && rkl2_reach(s - 1) >= ratio) --s;
  return s < 2 ? 2 : s;
}

// How a step of `ratio` explicit limits is taken with the fewest evaluations: forward-Euler substeps
// (ceil(ratio) of them) where they need no more than RKL2's stages (up to 4 limits), else RKL2.
struct SuperStepPlan {
  bool legendre;    // RKL2 (else forward-Euler substeps)
  int evaluations;  // its stages, or the substeps
};
inline SuperStepPlan super_step_plan(double ratio) {
  const int stages = rkl2_stages(ratio);
  const double substeps = std::max(1.0, std::ceil(ratio));
  if (substeps <= stages) return {false, static_cast<int>(substeps)};
  return {true, stages};
}

struct Rkl2Stage {
  double mu, nu, mu_tilde, gamma_tilde;  // of Y_(j-1), Y_(j-2), tau L(Y_(j-1)), tau L(Y_0)
  double start() const { return 1.0 - mu - nu; }  // of Y_0
};

// Stage j (1 <= j <= s) of an s-stage RKL2 step (s >= 2); stage 1 has only mu_tilde (mu = 1, nu = 0).
inline Rkl2Stage rkl2_stage(int s, int j) {
  const auto b = [](int k) { return k < 2 ? 1.0 / 3.0 : (k * k + k - 2.0) / (2.0 * k * (k + 1.0)); };
  const double w1 = 4.0 / (static_cast<double>(s) * s + s - 2.0);
  if (j == 1) return {1.0, 0.0, b(1) * w1, 0.0};
  const double mu = (2.0 * j - 1.0) / j * b(j) / b(j - 1);
  const double nu = -(j - 1.0) / j * b(j) / b(j - 2);
  const double mu_tilde = mu * w1;
  return {mu, nu, mu_tilde, -(1.0 - b(j - 1)) * mu_tilde};
}

// One part of the state (velocities, internal energies): y is advanced in place, the caller's
// rate() writes L(y) into l, and y0 holds Y_0, the values y starts the step with, unchanged until
// it ends (the caller's copy: the block steps' kick values; all three read through the vectors,
// which an evaluation may reallocate, e.g. adding ghosts behind the particles); l0 and prev (L(Y_0),
// Y_(j-2)) are scratch kept here.
template <class Y>
struct Rkl2Part {
  std::vector<Y>* y = nullptr;
  const std::vector<Y>* l = nullptr;
  const std::vector<Y>* y0 = nullptr;
  std::vector<Y> l0, prev;
  void bind(std::vector<Y>& values, const std::vector<Y>& rates, const std::vector<Y>& start, std::size_t n) {
    y = &values;
    l = &rates;
    y0 = &start;
    l0.resize(n);
    prev.resize(n);
  }
  std::size_t bytes() const { return (l0.capacity() + prev.capacity()) * sizeof(Y); }
};

// One step of the autonomous system dy/dt = L(y), each component i over its own tau(i) with its own
// plan_of(i) (d y_i / d sigma = tau(i) L_i(y) over sigma in [0, 1]). The components come ordered by
// their plans' evaluations, most first; the caller has made the first evaluation of all n (l holds
// L(Y_0)), and rate(m) makes the next ones, of the first m components. A component whose plan is
// done is seen by the others at its start value Y_0 until all are done (as block steps' active
// particles see inactive ones): the system the others go on with is then the same at each of their
// stages, which RKL2's stability needs (seen at its end value, a neighbour that jumps after the first
// evaluation makes the others overshoot). rate() is called evaluations - 1 times, `evaluations`
// being at least the most any component needs (every process of a distributed run calls it as
// often, some with m = 0).
// `each(m, f)` runs f(i) for i < m (a parallel loop: each component's arithmetic is its own, so the
// result does not depend on how the loop is split).
template <class PlanOf, class Tau, class Rate, class Each, class... Part>
void super_step(std::size_t n, int evaluations, PlanOf plan_of, Tau tau, Rate&& rate, Each&& each, Part&... parts) {
  each(n, [&](std::size_t i) { ((parts.l0[i] = (*parts.l)[i], parts.prev[i] = (*parts.y0)[i]), ...); });
  std::size_t m = n;
  for (int k = 0; k < evaluations; ++k) {
    if (k > 0) {
      while (m > 0 && plan_of(m - 1).evaluations <= k) --m;  // (ordered: most evaluations first)
      rate(m);
    }
    each(m, [&](std::size_t i) {
      const SuperStepPlan plan = plan_of(i);
      const double t = tau(i);
      const bool last = k == plan.evaluations - 1;
      if (!plan.legendre) {  // forward-Euler substeps of tau / m
        const double share = t / plan.evaluations;
        (((*parts.y)[i] += (*parts.l)[i] * share), ...);
      } else if (k == 0) {
        const double first = rkl2_stage(plan.evaluations, 1).mu_tilde * t;
        (((*parts.y)[i] = (*parts.y0)[i] + (*parts.l)[i] * first), ...);
      } else {
        const Rkl2Stage c = rkl2_stage(plan.evaluations, k + 1);
        const auto advance = [&](auto& part) {
          auto& y = (*part.y)[i];
          const auto next = y * c.mu + part.prev[i] * c.nu + (*part.y0)[i] * c.start() + (*part.l)[i] * (c.mu_tilde * t) +
                            part.l0[i] * (c.gamma_tilde * t);
          part.prev[i] = y;
          y = next;
        };
        (advance(parts), ...);
      }
      if (last) (((parts.prev[i] = (*parts.y)[i]), ((*parts.y)[i] = (*parts.y0)[i])), ...);  // kept aside
    });
  }
  each(n, [&](std::size_t i) { (((*parts.y)[i] = parts.prev[i]), ...); });
}

}  // namespace sphdisk
