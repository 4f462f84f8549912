#pragma once
// The terms one pair of particles (i, j) adds to the SPH sums (docs/physics.md sec. 2), one pure
// function per equation, on plain values: the pair loops (list_sums.hpp, density.hpp,
// viscous_stress.hpp) gather a pair's quantities, call these and add what they return. Where a loop
// visits each pair once, a function returns both particles' terms, or what they share. Only
// core/vec.hpp is used: the functions are constexpr and need no particles, lists or threads.
// Notation: dx = x_i - x_j, dv = v_j - v_i, F = F_ij the kernel-gradient factor (pair_factors.hpp),
// g = grad_i W_ij = dx F = -grad_j W_ji, V = m / rho a particle's volume, S the kinematic stress
// (viscous_stress.hpp), C = M^-1 the moment correction (moment_correction.hpp). The operations and
// their order are those the vector loops of list_sums_avx512_2d.cpp and _3d.cpp repeat, so both
// give the same bits.
#include <cmath>

#include "core/vec.hpp"

namespace sphdisk {

// What a pair adds to each of its two particles.
template <class T>
struct PairTerms {
  T to_i, to_j;
};

// Density (P98 eq. 4 with f = rho): m_j W_ij, j's term in rho_i; with one h, W_ij = W_ji and
// m_i W_ij is i's term in rho_j. The self term is density_term(m_i, W(0)).
constexpr double density_term(double m_other, double W) { return m_other * W; }

// grad_i W_ij = (x_i - x_j) F_ij (pair_factors.hpp).
template <int D>
constexpr Vec<D> kernel_gradient(const Vec<D>& dx, double F) {
  return dx * F;
}

// The mixed correction's sums (physics_params.hpp, GradientCorrection::Mixed) over the neighbours j:
// w = sum V_j W_ij, g = sum V_j grad_i W_ij, w_dv = sum V_j W_ij (v_j - v_i), w_dx = sum V_j W_ij
// (x_i - x_j). From them (mixed_gradient_sums) the sums of eq. 8 and M with grad_i W_ij - W_ij e_i
// in place of grad_i W_ij, e = g / w, follow without a second pass.
template <int D>
struct ShepardSums {
  double w = 0;
  Vec<D> g{}, w_dv{}, w_dx{};
};

// Eq. 8's sum V together with the moment matrix M_cb = -sum_j (m_j/rho_j) (W_,b / dx_b) dx_c dx_b of
// the same neighbours, in one pass. For a linear field v = G x, V = G M exactly. shepard: only with
// the mixed correction (zero otherwise).
template <int D>
struct GradientSums {
  Mat<D> V, M;
  ShepardSums<D> shepard;
};

// What the pair's two terms in eq. 8 and M share: dv (x) dx and dx (x) dx. Both particles get the
// same products: (v_i - v_j) (x) (x_j - x_i) = dv (x) dx.
template <int D>
constexpr GradientSums<D> gradient_pair_products(const Vec<D>& dv, const Vec<D>& dx) {
  GradientSums<D> q;
  for (int a = 0; a < D; ++a)
    for (int b = 0; b < D; ++b) {
      q.V(a, b) = dv[a] * dx[b];
      q.M(a, b) = dx[a] * dx[b];
    }
  return q;
}

// One particle's terms from the shared products, weighted with the partner's volume:
//   V += V_other F dv (x) dx        (eq. 8: (m_j/rho_j) (v_j - v_i) (x) grad_i W_ij),
//   M += -(V_other F dx (x) dx)     (docs/physics.md sec. 2, "Velocity gradient and stress").
// Adding the negated product gives the bits of subtracting it.
template <int D>
constexpr GradientSums<D> gradient_term(double F, double V_other, const GradientSums<D>& products) {
  const double w = F * V_other;
  GradientSums<D> t;
  for (std::size_t c = 0; c < t.V.c.size(); ++c) {
    t.V.c[c] = w * products.V.c[c];
    t.M.c[c] = -(w * products.M.c[c]);
  }
  return t;
}

// One particle's terms in the mixed correction's sums, from the pair's kernel value W and gradient
// g as that particle sees them: i gets shepard_term(W, V_j, g, dv, dx), j gets
// shepard_term(W, V_i, -g, -dv, -dx) (grad_j W_ji = -g; j sees v_i - v_j and x_j - x_i).
template <int D>
constexpr ShepardSums<D> shepard_term(double W, double V_other, const Vec<D>& g, const Vec<D>& dv, const Vec<D>& dx) {
  const double vw = V_other * W;
  return {vw, g * V_other, dv * vw, dx * vw};
}

// The sums of eq. 8 and M for the kernel gradient grad_i W_ij - W_ij e_i (e = shepard.g / shepard.w):
// V~ = V - w_dv (x) e and M~ = M + w_dx (x) e (M carries -dx (x) grad W). e: set to the shift used.
// Any shift keeps the sums exact for linear fields; the full one, g / w, also removes the zeroth
// moment. With it det M~ / det M = 1 + d, d = (g / w) . M^-1 w_dx (the matrix determinant lemma):
// few, one-sided neighbours (a sparse edge) can make d approach -1, M~ nearly singular, C~ = M~^-1
// huge and the viscous rates stiff. So where d < -1/4 the shift is scaled by s(-d) / (-d) with
// s(x) = 1/4 + 1/4 tanh(4 (x - 1/4)): det M~ / det M = 1 - s(-d) > 1/2 for every d, and s joins
// s(x) = x at 1/4 with equal first and second derivatives, so the rates stay smooth functions of the
// positions (and the time integration keeps its order). Where i has no neighbour or M is singular,
// e = 0: the linear correction.
inline constexpr double kMixedFullShiftReach = 0.25;

template <int D>
GradientSums<D> mixed_gradient_sums(const GradientSums<D>& s, Vec<D>& e) {
  e = Vec<D>{};
  Mat<D> C;
  if (!(s.shepard.w > 0) || !invert_if_well_conditioned(s.M, C)) return s;
  e = s.shepard.g * (1.0 / s.shepard.w);
  const double x = -dot(e, contract(C, s.shepard.w_dx)), x0 = kMixedFullShiftReach;
  if (x > x0) e *= (x0 + x0 * std::tanh((x - x0) / x0)) / x;
  GradientSums<D> t = s;
  for (int a = 0; a < D; ++a)
    for (int b = 0; b < D; ++b) {
      t.V(a, b) -= s.shepard.w_dv[a] * e[b];
      t.M(a, b) += s.shepard.w_dx[a] * e[b];
    }
  return t;
}

// The conservative form of eq. 6 without its masses: f = (S_i / rho_j + S_j / rho_i) . g, so that
// a_i += m_j f and a_j -= m_i f (antisymmetric: momentum exact). Pressure, if any, is subtracted
// from f before the masses (pressure_pair).
template <int D>
constexpr Vec<D> conservative_viscous_pair(const Mat<D>& Si, const Mat<D>& Sj, double inv_rho_i, double inv_rho_j,
                                           const Vec<D>& g) {
  Mat<D> X;
  for (std::size_t c = 0; c < X.c.size(); ++c) X.c[c] = Si.c[c] * inv_rho_j + Sj.c[c] * inv_rho_i;
  return contract(X, g);
}

// The corrected kernel gradients of a pair for the consistent divergence: i's C_i g and minus j's,
// -(C_j grad_j W_ji) = C_j g (physics_params.hpp, GradientCorrection::Linear).
template <int D>
constexpr PairTerms<Vec<D>> linear_corrected_gradients(const Mat<D>& Ci, const Mat<D>& Cj, const Vec<D>& g) {
  return {contract(Ci, g), contract(Cj, g)};
}

// The same with the mixed correction: C~_i (g - W e_i) = C~_i g - W s_i and -(C~_j (-g - W e_j)) =
// C~_j g + W s_j, with s = C~ e stored per particle (correction_shift).
template <int D>
constexpr PairTerms<Vec<D>> mixed_corrected_gradients(const Mat<D>& Ci, const Mat<D>& Cj, const Vec<D>& si,
                                                      const Vec<D>& sj, double W, const Vec<D>& g) {
  return {contract(Ci, g) - si * W, contract(Cj, g) + sj * W};
}

// The consistent divergence's viscous terms (docs/physics.md sec. 2, "Viscous force"):
//   a_i += V_j [S_j - S_i + S_i (ln rho_j - ln rho_i)] . G_i,
//   a_j += V_i [S_j - S_i + S_j (ln rho_j - ln rho_i)] . G_j     (dS and dl odd in i <-> j),
// with dl = ln rho_j - ln rho_i and G = {G_i, G_j} the corrected gradients above (G_j is minus j's
// own). Zero for a constant stress and density; for linear ones each particle's sum is their exact
// divergence (the corrections make the sums exact for linear fields).
template <int D>
constexpr PairTerms<Vec<D>> consistent_viscous_pair(const Mat<D>& Si, const Mat<D>& Sj, const PairTerms<Vec<D>>& G,
                                                    double dl, double Vi, double Vj) {
  Mat<D> Xi, Xj;
  for (std::size_t c = 0; c < Xi.c.size(); ++c) {
    const double dS = Sj.c[c] - Si.c[c];
    Xi.c[c] = dS + Si.c[c] * dl;
    Xj.c[c] = dS + Sj.c[c] * dl;
  }
  return {contract(Xi, G.to_i) * Vj, contract(Xj, G.to_j) * Vi};
}

// The moment-corrected, pair-symmetrised kernel gradient G_ij = (C_i + C_j) g / 2 (IAD0,
// moment_correction.hpp), which replaces g in the conservative form when sph.force_correction is
// on; G_ji = -G_ij keeps the conservation exact.
template <int D>
constexpr Vec<D> corrected_pair_gradient(const Mat<D>& Ci, const Mat<D>& Cj, const Vec<D>& g) {
  return (contract(Ci, g) + contract(Cj, g)) * 0.5;
}

// The pressure force without its masses: (P_i / rho_i^2 + P_j / rho_j^2) g, subtracted from the
// conservative form's f (a_i -= m_j (...) g, a_j += m_i (...) g; docs/physics.md sec. 2).
template <int D>
constexpr Vec<D> pressure_pair(double Pr_i, double Pr_j, const Vec<D>& g) {
  return g * (Pr_i + Pr_j);
}

// The pair's velocity along its separation, w = v_ij . x_ij / |x_ij| (xij = x_i - x_j, vij = v_i -
// v_j): negative for an approaching pair. Zero for a receding one, which the artificial viscosity and
// the signal speed below leave alone.
template <int D>
double approach_speed(const Vec<D>& xij, const Vec<D>& vij) {
  const double approach = dot(vij, xij);
  return approach < 0 ? approach / std::sqrt(norm2(xij)) : 0.0;
}

// Artificial viscosity (Monaghan 1997 with the signal velocity; Phantom's q_ab, Price et al. 2018
// eqs. 40-41): for an approaching pair, w = approach_speed < 0, each particle's
//   q_i / rho_i^2 = -1/2 f_i (alpha_i c_i + beta |w|) w / rho_i,
// zero for a receding pair (w = 0). Added to the particle's P / rho^2 in pressure_pair and
// pressure_work_pair it gives a repulsion along the pair, and its heating, with the pressure force's
// conservation. f: the Balsara limiter (1: none); alpha: each particle's own (viscosity_switch.hpp).
constexpr PairTerms<double> artificial_viscosity_pair(double w, double c_i, double c_j, double inv_rho_i, double inv_rho_j,
                                                      double f_i, double f_j, double alpha_i, double alpha_j, double beta) {
  return {-0.5 * f_i * (alpha_i * c_i - beta * w) * w * inv_rho_i, -0.5 * f_j * (alpha_j * c_j - beta * w) * w * inv_rho_j};
}

// The pair's signal speed for the step limit (timestep.hpp): the larger sound speed, plus beta times
// the approach speed |w| of an approaching pair.
constexpr double pair_signal_speed(double w, double c_i, double c_j, double beta) {
  return (c_i > c_j ? c_i : c_j) - beta * w;
}

// The pressure work of the pair, Pr = P / rho^2 and vij = v_i - v_j:
//   du_i/dt += Pr_i m_j vij . g,   du_j/dt += Pr_j m_i vij . g   ((v_j - v_i) . grad_j W_ji = vij . g).
template <int D>
constexpr PairTerms<double> pressure_work_pair(double Pr_i, double Pr_j, double m_i, double m_j, const Vec<D>& vij,
                                               const Vec<D>& g) {
  const double work = dot(vij, g);
  return {Pr_i * m_j * work, Pr_j * m_i * work};
}

// One particle's pair term in the heating that pairs with the force-corrected eq. 6
// (docs/physics.md sec. 2, "Viscous heating and pressure"): dv (x) C_other (dx F V_other), i.e.
// (m_j/rho_j) (v_j - v_i) (x) C_j grad_i W_ij for i, and for j with i's C and volume (the same dv
// and dx: (v_i - v_j) (x) C_i (-dx) F = dv (x) C_i dx F).
template <int D>
constexpr Mat<D> corrected_heating_term(const Mat<D>& C_other, double F, double V_other, const Vec<D>& dv,
                                        const Vec<D>& dx) {
  const Vec<D> g = contract(C_other, dx * (F * V_other));
  Mat<D> H;
  for (int a = 0; a < D; ++a)
    for (int b = 0; b < D; ++b) H(a, b) = dv[a] * g[b];
  return H;
}

}  // namespace sphdisk
