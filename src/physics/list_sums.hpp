#pragma once
// The innermost loops of the velocity-gradient (P98 eq. 8) and force (eq. 6) pair sums: the terms
// of one half list, particle i and its partners js[q] with kernel-gradient factors F[q]
// (pair_factors.hpp), added to i's running sum and to each writable partner's stored sum; each
// pair's terms are those of pair_terms.hpp. They are most of a rate evaluation's pair work. In
// scalar code each pair's terms are gathered, formed and scattered one at a time. On CPUs with
// AVX-512 (asked at run time, core/vector_isa.hpp) the 2D gradient and force loops and the 3D force
// loop gather eight partners and form their terms at once, then add them pair by pair in list
// order, and the 3D gradient loop forms each pair's 18 products in three vectors; with AVX2 only,
// the scalar gradient loop runs compiled for AVX2 (the forces the scalar loop). Every path gives the
// same bits: the same operations in the same order (i's sum takes the partners in list order; a
// partner's sum gets one addition per pair, as in the scalar loop), with floating-point contraction
// off in list_sums.cpp and list_sums_avx512_2d.cpp / _3d.cpp, and the tests compare them.
// add_gradient_list and add_force_list (below) name the cases the vector paths cover; the rest
// runs the scalar loop.
#include <cstddef>
#include <cstdint>
#include <cmath>
#include <span>

#include "core/overwrite_vector.hpp"
#include "core/particles.hpp"
#include "core/vec.hpp"
#include "physics/kernels.hpp"
#include "physics/lane_sums.hpp"
#include "physics/pair_factors.hpp"
#include "physics/pair_terms.hpp"

namespace sphdisk {

// A particle's eq. 8 sum V and moment matrix M as an evaluation keeps them (GradientSums without
// the Shepard sums).
template <int D>
struct GradientMoments {
  Mat<D> V, M;
};

// The writable particles' sums of an evaluation: zeroed in parallel by zero_sums (viscous_stress.hpp),
// so a new buffer is not zero-filled first (core/overwrite_vector.hpp). V and M for each; the mixed
// correction's Shepard sums, which only it reads, in an array of their own that is empty otherwise
// (56 of 120 bytes per particle in 2D).
template <int D>
struct GradientSumsArray {
  UnsetVector<GradientMoments<D>> moments;
  UnsetVector<ShepardSums<D>> shepard;
  // Particle i's sums (its Shepard sums zero where they are not kept).
  GradientSums<D> operator[](std::size_t i) const {
    GradientSums<D> s{moments[i].V, moments[i].M, {}};
    if (!shepard.empty()) s.shepard = shepard[i];
    return s;
  }
  bool empty() const { return moments.empty(); }
  std::size_t bytes() const {
    return moments.capacity() * sizeof(GradientMoments<D>) + shepard.capacity() * sizeof(ShepardSums<D>);
  }
};

// Adds a pair term to a sum, component by component.
inline void accumulate(double& into, double x) { into += x; }

template <int D>
void accumulate(Mat<D>& into, const Mat<D>& x) {
  for (std::size_t c = 0; c < into.c.size(); ++c) into.c[c] += x.c[c];
}

template <int D>
void accumulate(ShepardSums<D>& into, const ShepardSums<D>& x) {
  into.w += x.w;
  into.g += x.g;
  into.w_dv += x.w_dv;
  into.w_dx += x.w_dx;
}

template <int D>
void accumulate(GradientSums<D>& into, const GradientSums<D>& x) {
  accumulate(into.V, x.V);
  accumulate(into.M, x.M);
  accumulate(into.shepard, x.shepard);
}

// The V and M of a term, added to the sums an evaluation keeps (GradientSumsArray).
template <int D>
void accumulate(GradientMoments<D>& into, const GradientSums<D>& x) {
  accumulate(into.V, x.V);
  accumulate(into.M, x.M);
}

// The pair's kernel values (pair_factors.hpp) from the particles' kernel scales.
[[gnu::always_inline]] inline PairValues pair_kernel_values(KernelType kernel, const KernelScale& si, const KernelScale& sj,
                                                            double r) {
  return with_kernel(kernel, [&](auto k) { return pair_kernel_values<decltype(k)>(si, sj, r); });
}

// What the gradient sums of a list read and write: sums[j] (and shepard[j]) for the partners
// j < writable. scales: every particle's kernel scale, where the mixed correction's sums are wanted
// (else null, and shepard is not written).
template <int D>
struct GradientListData {
  const Vec<D>* pos;
  const Vec<D>* vel;
  const double* volume;
  GradientMoments<D>* sums;
  std::size_t writable;
  const KernelScale* scales = nullptr;
  KernelType kernel = KernelType::Cubic;
  ShepardSums<D>* shepard = nullptr;
};

// (always_inline: list_sums.cpp compiles it for AVX2 too.)
template <int D>
[[gnu::always_inline]] inline void add_gradient_list_scalar(const GradientListData<D>& d, std::uint32_t i, std::span<const std::uint32_t> js,
                              std::span<const float> F, GradientSums<D>& sum_i) {
  const Vec<D> xi = d.pos[i], vi = d.vel[i];
  const double Vi = d.volume[i];
  for (std::size_t q = 0; q < js.size(); ++q) {
    const std::uint32_t j = js[q];
    const Vec<D> dv = d.vel[j] - vi, dx = xi - d.pos[j];
    const GradientSums<D> shared = gradient_pair_products(dv, dx);
    const double f = static_cast<double>(F[q]);
    GradientSums<D> ti = gradient_term(f, d.volume[j], shared), tj = gradient_term(f, Vi, shared);
    if (d.scales) {
      const double W = pair_average_value(pair_kernel_values(d.kernel, d.scales[i], d.scales[j], std::sqrt(norm2(dx))));
      const Vec<D> g = kernel_gradient(dx, f);
      ti.shepard = shepard_term(W, d.volume[j], g, dv, dx);
      tj.shepard = shepard_term(W, Vi, -g, -dv, -dx);
      accumulate(sum_i, ti);
      if (j < d.writable) accumulate(d.sums[j], tj), accumulate(d.shepard[j], tj.shepard);
    } else {  // (the Shepard sums stay zero: only V and M)
      accumulate(sum_i.V, ti.V), accumulate(sum_i.M, ti.M);
      if (j < d.writable) accumulate(d.sums[j], tj);
    }
  }
}

// What the scatter-density sums of a list (scatter_density.hpp) read and write: sums[j] for the
// partners j < writable; scales: every particle's kernel scale.
template <int D>
struct ScatterListData {
  const Vec<D>* pos;
  const double* mass;
  const KernelScale* scales;
  double* sums;
  std::size_t writable;
  KernelType kernel = KernelType::Cubic;
};

// Each pair's two kernel values: i gets m_j W(r, h_j), a writable j gets m_i W(r, h_i)
// (density_term, pair_terms.hpp). (always_inline: list_sums.cpp dispatches to it.)
template <class K, int D>
[[gnu::always_inline]] inline void add_scatter_list_scalar(const ScatterListData<D>& d, std::uint32_t i,
                                                           std::span<const std::uint32_t> js, double& sum_i) {
  const Vec<D> xi = d.pos[i];
  const double mi = d.mass[i];
  LaneSum lanes;  // i's sum (lane_sums.hpp)
  for (std::size_t q = 0; q < js.size(); ++q) {
    const std::uint32_t j = js[q];
    const PairValues w = pair_kernel_values<K>(d.scales[i], d.scales[j], std::sqrt(norm2(xi - d.pos[j])));
    lanes.add(q, density_term(d.mass[j], w.j));
    if (j < d.writable) d.sums[j] += density_term(mi, w.i);
  }
  sum_i += lanes.total();
}

// What the forces of a list read and write: acc[j] (and du_dt[j] with pressure) for j < writable.
// inv_rho: 1 / rho (read by the conservative divergence and with pressure); p_over_rho2: P / rho^2
// (read only with pressure); correction: read only with force_correction or the consistent
// divergence; log_rho: ln rho and volume: m / rho (read only with the consistent divergence);
// du_dt: null where the particles hold no energy rate (no energy equation: the pressure work is
// not kept).
template <int D>
struct ForceListData {
  const Vec<D>* pos;
  const Vec<D>* vel;
  const Mat<D, ReducedReal>* stress;
  const Mat<D, ReducedReal>* correction;
  const double* mass;
  const double* inv_rho;
  const double* p_over_rho2;
  Vec<D>* acc;
  double* du_dt;
  std::size_t writable;
  bool with_pressure, force_correction;
  const double* log_rho = nullptr;
  bool consistent = false;
  // PairDensity::Others (physics_params.hpp): rho_i - m_i W(0, h_i) per particle; null: the summed
  // densities' ratio.
  const double* rho_without_self = nullptr;
  // GradientCorrection::Mixed: C~_i e_i per particle (correction_shift); null: the linear correction.
  const Vec<D>* correction_shift = nullptr;
  // Every particle's kernel scale (with either of the two above), and the kernel.
  const KernelScale* scales = nullptr;
  KernelType kernel = KernelType::Cubic;
  // Artificial viscosity (with pressure): every particle's sound speed, limiter (null: 1; read
  // as the stress is, after the particle's velocity gradient) and alpha, beta, and the signal
  // speeds raised to each pair's (j's for j < writable); null: none.
  const double* sound_speed = nullptr;
  const double* limiter = nullptr;
  const double* av_alpha = nullptr;
  double av_beta = 0.0;
  double* signal_speed = nullptr;
  const double* volume = nullptr;
};

// ln(rho_j / rho_i) of the densities without the pair's own terms (PairDensity::Others):
// rho_i - m_i W(0, h_i) - m_j W(r, h_i) over the same for j, with w the pair's kernel values; where
// either is not positive (a particle with no other neighbour) the summed densities' ratio.
template <int D>
[[gnu::always_inline]] inline double others_log_ratio(const ForceListData<D>& d, std::uint32_t i, std::uint32_t j,
                                                      const PairValues& w, double summed) {
  const double rho_i = d.rho_without_self[i] - d.mass[j] * w.i, rho_j = d.rho_without_self[j] - d.mass[i] * w.j;
  return rho_i > 0 && rho_j > 0 ? std::log(rho_j / rho_i) : summed;
}

// The pair terms of forces.hpp (eq. 6 and the pressure force) for one list: i's to ai and du_i.
// The switches are template arguments so that each case runs a loop without the others' tests
// (force_list_terms), chosen once per list by add_force_list_scalar. Correction: the force
// correction of the conservative divergence; Consistent: the consistent divergence (then
// Correction is false), whose pair terms, viscous and pressure together, i sums in eight lanes
// (lane_sums.hpp) and each partner takes as one term.
template <int D, bool Pressure, bool Correction, bool Consistent = false>
void force_list_terms(const ForceListData<D>& d, std::uint32_t i, std::span<const std::uint32_t> js,
                      std::span<const float> F, Vec<D>& ai, double& du_i) {
  const Vec<D> xi = d.pos[i], vi = d.vel[i];
  const Mat<D> Si = as_double(d.stress[i]);
  const double mi = d.mass[i], inv_rho_i = d.inv_rho ? d.inv_rho[i] : 0.0;
  const double Pr_i = Pressure ? d.p_over_rho2[i] : 0.0;
  Mat<D> Ci;
  double log_rho_i = 0.0, signal_i = 0.0;
  if constexpr (Consistent) Ci = as_double(d.correction[i]), log_rho_i = d.log_rho[i];
  LaneSums<D> lanes;  // Consistent: i's sums
  for (std::size_t q = 0; q < js.size(); ++q) {
    const std::uint32_t j = js[q];
    Vec<D> g = kernel_gradient(xi - d.pos[j], static_cast<double>(F[q]));
    if constexpr (Correction) g = corrected_pair_gradient(as_double(d.correction[i]), as_double(d.correction[j]), g);
    const Mat<D> Sj = as_double(d.stress[j]);
    const double mj = d.mass[j];
    Vec<D> f;  // the pair's antisymmetric part: a_i += m_j f, a_j -= m_i f
    PairTerms<Vec<D>> a;  // Consistent: the viscous terms of i and j
    if constexpr (Consistent) {
      double dl = d.log_rho[j] - log_rho_i;
      // The pair's kernel values, one evaluation for both their readers.
      const PairValues w =
          d.scales ? pair_kernel_values(d.kernel, d.scales[i], d.scales[j], std::sqrt(norm2(xi - d.pos[j]))) : PairValues{};
      if (d.rho_without_self) dl = others_log_ratio(d, i, j, w, dl);
      const Mat<D> Cj = as_double(d.correction[j]);
      const PairTerms<Vec<D>> G = d.correction_shift ? mixed_corrected_gradients(Ci, Cj, d.correction_shift[i],
                                                                                 d.correction_shift[j], pair_average_value(w), g)
                                                     : linear_corrected_gradients(Ci, Cj, g);
      a = consistent_viscous_pair(Si, Sj, G, dl, d.volume[i], d.volume[j]);
    } else {
      f = conservative_viscous_pair(Si, Sj, inv_rho_i, d.inv_rho[j], g);
    }
    if constexpr (Pressure) {
      const Vec<D> xij = xi - d.pos[j], vij = vi - d.vel[j];
      PairTerms<double> Pr{Pr_i, d.p_over_rho2[j]};
      if (d.sound_speed) {  // artificial viscosity: q / rho^2 on top of P / rho^2
        const double ci = d.sound_speed[i], cj = d.sound_speed[j], w = approach_speed(xij, vij);
        const PairTerms<double> av = artificial_viscosity_pair(w, ci, cj, inv_rho_i, d.inv_rho[j], d.limiter ? d.limiter[i] : 1.0,
                                                              d.limiter ? d.limiter[j] : 1.0, d.av_alpha[i], d.av_alpha[j], d.av_beta);
        Pr.to_i += av.to_i, Pr.to_j += av.to_j;
        const double s = pair_signal_speed(w, ci, cj, d.av_beta);
        signal_i = std::max(signal_i, s);
        if (j < d.writable) d.signal_speed[j] = std::max(d.signal_speed[j], s);
      }
      f -= pressure_pair(Pr.to_i, Pr.to_j, g);
      const PairTerms<double> work = pressure_work_pair(Pr.to_i, Pr.to_j, mi, mj, vij, g);
      if constexpr (Consistent) lanes.add(q, work.to_i);
      else du_i += work.to_i;
      if (j < d.writable && d.du_dt) d.du_dt[j] += work.to_j;
    }
    if constexpr (Consistent) {
      if constexpr (Pressure) a.to_i += f * mj, a.to_j -= f * mi;
      lanes.add(q, a.to_i);
      if (j < d.writable) d.acc[j] += a.to_j;
    } else {
      ai += f * mj;
      if (j < d.writable) d.acc[j] -= f * mi;
    }
  }
  if constexpr (Consistent) lanes.add_to(ai, du_i);
  if (d.signal_speed && i < d.writable) d.signal_speed[i] = std::max(d.signal_speed[i], signal_i);
}

template <int D>
void add_force_list_scalar(const ForceListData<D>& d, std::uint32_t i, std::span<const std::uint32_t> js,
                           std::span<const float> F, Vec<D>& ai, double& du_i) {
  if (d.consistent) {
    if (d.with_pressure) return force_list_terms<D, true, false, true>(d, i, js, F, ai, du_i);
    return force_list_terms<D, false, false, true>(d, i, js, F, ai, du_i);
  }
  if (d.with_pressure) {
    if (d.force_correction) return force_list_terms<D, true, true>(d, i, js, F, ai, du_i);
    return force_list_terms<D, true, false>(d, i, js, F, ai, du_i);
  }
  if (d.force_correction) return force_list_terms<D, false, true>(d, i, js, F, ai, du_i);
  force_list_terms<D, false, false>(d, i, js, F, ai, du_i);
}

// The vector paths where the CPU has AVX-512 (gradient: or AVX2) and the case is covered, else the
// scalar loop. Gradient: without the mixed correction's sums. Force: in 2D without force correction,
// eq. 6's conservative form without pressure, and the consistent one with the linear correction and
// the ln rho of log_rho (summed or scatter densities), with or without pressure but without the
// artificial viscosity (the rings' cases); in 3D with pressure the conservative form, with or
// without the artificial viscosity, and the consistent one without it (the disc's and 3D ring's cases).
template <int D>
void add_gradient_list(const GradientListData<D>& d, std::uint32_t i, std::span<const std::uint32_t> js,
                       std::span<const float> F, GradientSums<D>& sum_i);
// Scatter density: in 2D with the cubic kernel on AVX-512.
template <int D>
void add_scatter_list(const ScatterListData<D>& d, std::uint32_t i, std::span<const std::uint32_t> js, double& sum_i);
void add_force_list(const ForceListData<2>& d, std::uint32_t i, std::span<const std::uint32_t> js, std::span<const float> F,
                    Vec<2>& ai, double& du_i);
void add_force_list(const ForceListData<3>& d, std::uint32_t i, std::span<const std::uint32_t> js, std::span<const float> F,
                    Vec<3>& ai, double& du_i);

}  // namespace sphdisk
