#pragma once
// Variable smoothing lengths (Springel & Hernquist 2002; Price 2012, as in Phantom and GADGET):
// each particle's h solves
//   h_i = eta (m_i / rho_i)^(1/D),   rho_i = sum_j m_j W(|x_i - x_j|, h_i)   (self term included),
// so every kernel holds about the same number of neighbours, N_ngb = V_D (2 eta)^D with V_D the
// volume of the unit ball. Why: with one global h (P98 sec. 5.3) the ring's wings, where Sigma
// falls by orders of magnitude, hold a handful of neighbours, the self term m W(0) floors their
// density, and the viscous torque there is too weak: the wings stay truncated
// (docs/validation.md). With h adapting, the resolution follows the mass.
// The equation is solved per particle by Newton-Raphson on f(h) = rho(h) - m (eta/h)^D, safeguarded
// by bisection on the bracket of sign changes, over the candidates the neighbour search hands over
// (neighbour_lists.hpp, build_settled_neighbour_lists). The iteration is the same for any thread
// count, and so is the result.
// The solve hands over rho_i = sum_j m_j W(r_ij, h_i) with h_i (to ~1e-7 relative at most, see
// smoothing_length_at), so the density loop need not sum it again (density.hpp). Phantom, too,
// takes rho from the h solve, there as m (eta/h)^D.
// Reads: pos, mass, h (start value). The caller stores h and rho.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/particles.hpp"
#include "core/snug_resize.hpp"
#include "parallel/loops.hpp"
#include "physics/kernel_terms.hpp"
#include "physics/kernels.hpp"

namespace sphdisk {

// eta for a target neighbour number: N_ngb = V_D (2 eta)^D.
template <int D>
double eta_for_neighbours(double neighbours) {
  const double unit_ball = D == 1 ? 2.0 : D == 2 ? std::numbers::pi : 4.0 / 3.0 * std::numbers::pi;
  return 0.5 * std::pow(neighbours / unit_ball, 1.0 / D);
}

// The particles' common mass, or 0 if they differ (or there are none).
template <int D>
double uniform_mass_of(const Particles<D>& p) {
  if (p.size() == 0) return 0.0;
  const double m = p.mass[0];
  const std::size_t others = par::sum<std::size_t>(p.size(), [&](std::size_t i) { return std::size_t{p.mass[i] != m}; });
  return others == 0 && m > 0 ? m : 0.0;
}

struct SmoothingLengthResult {
  double h;
  double rho;              // sum_j m_j W(r_ij, h), self term included (beyond the candidates: at h_max)
  bool beyond_candidates;  // the solution needs neighbours beyond the candidate radius: h is a new start value
  int sums;                // density sums over the candidates it took (one per Newton iterate)
};

// The start value of a particle's next solve. GADGET and SWIFT drift h between solves with
// dh/dt = -(h/D) div v; here h is extrapolated from the particle's last three solutions instead
// (quadratic at equal intervals: exact while h changes quadratically in time), which needs neither
// the time step nor div v. From the previous h alone the first Newton step on the ring is 1e-3 to
// 1e-2 of h, above the solve's 1e-4 tolerance, so nearly every solve would take two density sums;
// from the extrapolated start, one (docs/performance.md, "Smoothing-length solve"). The start only
// sets where Newton begins: the solution is the same to ~(1e-4)^2 relative. Where intervals differ
// (a particle changing its time bin, Runge-Kutta stages) the extrapolation is poorer, hence
// limited to 5% of h.
// History (Particles::h_prev, h_prev2, zero in new particles): h_prev > 0 is the solution before h,
// h_prev < 0 says h is a solution with none before it, h_prev = 0 that h is an initial guess;
// h_prev2 > 0 is the solution before h_prev.
inline double predicted_smoothing_length(double h, double h_prev, double h_prev2) {
  if (!(h_prev > 0)) return h;
  const double extrapolated = h_prev2 > 0 ? 3.0 * h - 3.0 * h_prev + h_prev2 : 2.0 * h - h_prev;
  return std::clamp(extrapolated, h / 1.05, 1.05 * h);
}

// Shifts the history when a solve replaces h (the value before the solve).
inline void remember_smoothing_length(double h, double& h_prev, double& h_prev2) {
  h_prev2 = h_prev > 0 ? h_prev : 0.0;
  h_prev = h_prev == 0 ? -1.0 : h;
}

// Solves for h_i from h_start with candidates (every j within 2 h_max of x_i). tolerance: on the
// relative Newton step (Phantom uses 1e-4). The step that falls below it is still taken; the unit
// tests check that h then solves the density equation to 1e-6 (with 1e-3 here some particles were
// 3e-3 off, so the tolerance is not loosened to save iterations).
// dist2: the candidates' squared distances |x_i - x_j|^2 where the search has them, else empty.
// uniform_mass: every particle's mass where all are equal (uniform_mass_of), else 0.
template <class K, int D>
SmoothingLengthResult smoothing_length_at(std::size_t i, const Particles<D>& p, std::span<const std::uint32_t> cand,
                                          std::span<const double> dist2, double h_start, double eta, double h_max,
                                          double uniform_mass, double tolerance = 1e-4) {
  // m_j and r_ij once; every iteration re-reads them contiguously. Equal masses are factored out of
  // the sums instead (m sum_j w_j: no gather, fill or product per candidate; the gather's scattered
  // loads were a fifth of the solve).
  thread_local std::vector<double> mass_buffer, dist_buffer;
  const bool uniform = uniform_mass > 0;
  double* mass = uniform ? nullptr : scratch_for(mass_buffer, cand.size());
  double* dist = scratch_for(dist_buffer, cand.size());
  if (!uniform)
    for (std::size_t k = 0; k < cand.size(); ++k) mass[k] = p.mass[cand[k]];
  if (dist2.size() == cand.size()) {
    square_roots(dist2.data(), cand.size(), dist);  // kernel_terms.hpp
  } else {
    for (std::size_t k = 0; k < cand.size(); ++k) dist[k] = norm(p.pos[i] - p.pos[cand[k]]);
  }
  const double mi = p.mass[i];
  // rho(h) and d rho/dh: sum_j m_j w(q_j) and sum_j m_j (D w(q_j) + q_j w'(q_j)) (the latter is
  // -h^(D+1)/sigma d rho/dh). The kernel terms first, candidate by candidate into two buffers: a loop
  // without a sum, which vectorises (with the sums in it, it did not: ~14 instructions per candidate
  // for w alone). Then the sums, in four interleaved partial sums added in a fixed order, one
  // vector of four (kernel_terms.hpp, kernel_sums).
  thread_local std::vector<double> w_buffer, dw_buffer;
  double* wq = scratch_for(w_buffer, cand.size());
  double* dwq = scratch_for(dw_buffer, cand.size());
  const auto density_at = [&](double h) {
    const double inv_h = 1.0 / h;
    const KernelSums s = kernel_sums<K, D>(dist, mass, inv_h, cand.size(), wq, dwq);
    const double scale = uniform ? uniform_mass : 1.0;
    const double sum_w = scale * s.w, sum_dw = scale * s.dw;
    const double self = mi * K::w(0.0);
    const double sw = self + sum_w;
    const double sdw = D * self + sum_dw;
    double norm = K::template sigma<D>();
    for (int d = 0; d < D; ++d) norm *= inv_h;
    return std::pair{norm * sw, -norm * inv_h * sdw};
  };
  double h = std::min(h_start, h_max), lo = 0.0, hi = std::numeric_limits<double>::infinity();
  for (int iter = 0;; ++iter) {
    const auto [rho, drho] = density_at(h);
    double rho_h = mi;  // m (eta / h)^D
    for (int d = 0; d < D; ++d) rho_h *= eta / h;
    const double f = rho - rho_h, df = drho + D * rho_h / h;
    (f < 0 ? lo : hi) = h;
    double next = df > 0 ? h - f / df : -1.0;
    // Newton leaving the bracket falls back to bisection (doubling while no upper bound is known).
    // The bracket is closed: from a start at the root to round-off, f / df is below h's last digit
    // and the step returns h itself, which is the bound just set.
    if (!(next >= lo && next <= hi && next > 0)) next = std::isfinite(hi) ? 0.5 * (lo + hi) : 2.0 * h;
    if (next > h_max) {
      // Newton may overshoot: only f(h_max) < 0 proves the root lies beyond the candidates.
      if (h >= h_max) return {2.0 * h_max, rho, true, iter + 1};
      next = h_max;
    }
    // The step is taken, and rho follows it to first order: off from the sum at the new h by
    // ~ (D (D + 1) / 2) (step / h)^2 relative, ~1e-7 at most for steps below 1e-4 (the unit tests compare
    // with brute-force sums: at most 2e-8 in 2D, 1e-7 in 3D).
    if (std::abs(next - h) <= tolerance * h) return {next, rho + drho * (next - h), false, iter + 1};
    if (iter == 99) return {h, rho, false, iter + 1};  // a safeguard only: Newton with bisection converges in a few steps
    h = next;
  }
}

}  // namespace sphdisk
