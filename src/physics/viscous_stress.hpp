#pragma once
// Velocity gradient, shear and viscous stress of each particle (P98 eqs. 2, 7, 8).
//   V_ab,i     = sum_j (m_j / rho_j) (v_a,j - v_a,i) W_,b           (eq. 8, W_,b = d W_ij / d x_i,b)
//   sigma_ab,i = V_ab,i + V_ba,i - (2/3) delta_ab V_gg,i             (eq. 7; 2/3 also in 2D, docs/physics.md sec. 1)
//   S_i        = t_i / rho_i = nu sigma_i + nu_bulk delta tr(V_i)    (eq. 2 divided by rho)
// Storing the kinematic stress S = t / rho lets the force loop use eq. 6 as written:
//   m_j (nu_j sigma_j / rho_i + nu_i sigma_i / rho_j) = m_j (S_j / rho_i + S_i / rho_j).
// Viscous heating du_i/dt = S_i : V_i (docs/physics.md sec. 2: sigma:V, not sigma:sigma/2) makes
// the kinetic + internal energy exactly conserved together with the force of forces.hpp.
// Pair sums visit each pair once (pair_lists.hpp); each pair's terms are those of pair_terms.hpp.
// Reads: pos, vel, volume, pair factors. Writes: stress, du_dt (viscous heating part, where the particles
// hold it: with an energy equation).
#include "core/pair_source.hpp"
#include "core/particles.hpp"
#include "core/snug_resize.hpp"
#include "parallel/loops.hpp"
#include "physics/kernel_scales.hpp"
#include "physics/list_sums.hpp"
#include "physics/moment_correction.hpp"
#include "physics/pair_factors.hpp"
#include "physics/physics_params.hpp"
#include "physics/scatter_density.hpp"

namespace sphdisk {

// Per-particle sums over each half list's pairs (pair_lists.hpp): add_list(i, js, F, sum_i) adds
// the list's terms to sum_i and to the writable partners' sums. Sums are kept for the writable
// particles (pairs.writable()) and zeroed first, in parallel (grow_snug: entries beyond the
// writable ones are stale).
// The far pairs come first (FarPairs::First), so that a particle's sums are complete once the tiles
// around it have passed (pair_scan.hpp joins the force loop to the gradient loop that way).
template <class T, class A>
void zero_sums(std::size_t m, std::vector<T, A>& sums) {
  grow_snug(sums, m);
  par::for_each(m, [&](std::size_t i) { sums[i] = T{}; }, "velocity_gradient");
}

// The list loop's body: f(i, js, F) of Pairs::for_each_list.
template <class T, class A, class AddList>
auto sum_lists_into(std::vector<T, A>& sums, std::size_t m, AddList add_list) {
  return [&sums, m, add_list](std::uint32_t i, std::span<const std::uint32_t> js, std::span<float> F) {
    T sum_i{};
    add_list(i, js, std::span<const float>(F), sum_i);
    if (i < m) accumulate(sums[i], sum_i);
  };
}

// The same for the velocity-gradient sums: V and M, and the Shepard sums where shepard is true
// (else released).
template <int D>
void zero_sums(std::size_t m, GradientSumsArray<D>& sums, bool shepard) {
  zero_sums(m, sums.moments);
  if (shepard) zero_sums(m, sums.shepard);
  else release_memory(sums.shepard);
}

template <int D, class AddList>
auto sum_lists_into(GradientSumsArray<D>& sums, std::size_t m, AddList add_list) {
  return [&sums, m, add_list](std::uint32_t i, std::span<const std::uint32_t> js, std::span<float> F) {
    GradientSums<D> sum_i{};
    add_list(i, js, std::span<const float>(F), sum_i);
    if (i >= m) return;
    accumulate(sums.moments[i], sum_i);
    if (!sums.shepard.empty()) accumulate(sums.shepard[i], sum_i.shepard);
  };
}

template <class Pairs, class T, class A, class AddList>
void sum_pair_lists(const Pairs& pairs, std::vector<T, A>& sums, AddList&& add_list) {
  const std::size_t m = pairs.writable();
  zero_sums(m, sums);
  pairs.for_each_list(sum_lists_into(sums, m, std::forward<AddList>(add_list)), FactorUse::Read, "velocity_gradient",
                      FarPairs::First);
}

// Eq. 8's V and the moment matrix M of a list's pairs (the list loops: list_sums.hpp), for sums
// sized for the m writable particles (zero_sums); with the mixed correction also its Shepard sums
// (scales: every particle's kernel scale, kernel_scales.hpp).
template <int D>
auto gradient_pair_terms(const Particles<D>& p, GradientSumsArray<D>& sums, std::size_t m, const PhysicsParams& phys,
                         const KernelScale* scales) {
  const bool mixed = phys.gradient_correction == GradientCorrection::Mixed;
  return [&p, &sums, m, mixed, scales, kernel = phys.kernel](std::uint32_t i, std::span<const std::uint32_t> js,
                                                            std::span<const float> F, GradientSums<D>& sum_i) {
    const GradientListData<D> d{p.pos.data(), p.vel.data(), p.volume.data(), sums.moments.data(), m,
                                mixed ? scales : nullptr, kernel, mixed ? sums.shepard.data() : nullptr};
    add_gradient_list(d, i, js, F, sum_i);
  };
}

// The gradient made exact for linear velocity fields on any particle set: V M^-1. M is the
// identity only for a complete, regular sampling. Why: the ring's particles are placed at random
// (P98 5.2) and stay disordered (no pressure), and for such sets the summation density carries the
// self term m W(0) on top of the smoothed density, ~10% at 60 neighbours; the volumes m/rho and
// with them eq. 8's gradient come out that much too small, the effective viscosity too, and the
// ring spreads too slowly at every N (docs/validation.md). M carries the same factor, so V M^-1
// cancels it, as it cancels the missing support at the ring's edges. Falls back to eq. 8 where M
// is singular (fewer than D neighbours in general position).
template <int D>
Mat<D> corrected_gradient(const GradientSums<D>& g) {
  Mat<D> Minv;
  if (!invert_if_well_conditioned(g.M, Minv)) return g.V;
  return g.V * Minv;
}

// The Balsara (1995) limiter of the artificial viscosity, |div v| / (|div v| + |curl v| + 1e-4 c / h),
// from the velocity gradient V (V_ab = d v_a / d x_b): near 1 in compression, near 0 in shear, as in
// a Keplerian disc.
template <int D>
double balsara_limiter(const Mat<D>& V, double c, double h) {
  const double div = std::abs(V.trace());
  double curl2 = 0;
  for (int a = 0; a < D; ++a)
    for (int b = a + 1; b < D; ++b) curl2 += (V(b, a) - V(a, b)) * (V(b, a) - V(a, b));
  return div / (div + std::sqrt(curl2) + 1e-4 * c / h);
}

// Eq. 7 divided by rho, with the particle's shear viscosity nu (shear_viscosity_at).
template <int D>
Mat<D> kinematic_stress(const Mat<D>& V, double nu, const PhysicsParams& phys) {
  const double div = V.trace();
  Mat<D> S;
  for (int a = 0; a < D; ++a)
    for (int b = 0; b < D; ++b) S(a, b) = nu * (V(a, b) + V(b, a));
  for (int a = 0; a < D; ++a) S(a, a) += (bulk_viscosity_for(phys, nu) - 2.0 / 3.0 * nu) * div;
  return S;
}

// Particle i's stress and heating from its complete gradient sums g.
template <int D>
void settle_stress(Particles<D>& p, std::size_t i, const GradientSums<D>& g, const PhysicsParams& phys) {
  // With the mixed correction the velocity gradient and the consistent divergence's C come from the
  // Shepard-shifted sums (pair_terms.hpp, mixed_gradient_sums), and s = C~ e is kept for the
  // divergence's pairs (correction_shift).
  const bool mixed = phys.gradient_correction == GradientCorrection::Mixed;
  Vec<D> e;
  const GradientSums<D> used = mixed ? mixed_gradient_sums(g, e) : g;
  // The heating reads S and C as stored, as the force loop does (in single precision: rounded),
  // so that kinetic + internal energy stay exactly conserved.
  const Mat<D> V = phys.gradient_correction == GradientCorrection::None ? g.V : corrected_gradient(used);
  const Mat<D> S = store_and_read(p.stress[i], kinematic_stress(V, shear_viscosity_at(phys, p.pos[i]), phys));
  if (phys.artificial_viscosity()) {
    if (phys.av_limiter) p.av_limiter[i] = balsara_limiter(V, particle_sound_speed(p, i, phys), p.h[i]);
    p.compression[i] = std::max(-V.trace(), 0.0);  // drives the switch (viscosity_switch.hpp)
  }
  const bool heating = !p.du_dt.empty();  // absent without an energy equation (core/particles.hpp)
  if (phys.force_correction) {
    const Mat<D> C = store_and_read(p.correction[i], correction_from_moments(g.M));
    if (heating) p.du_dt[i] = 0.5 * double_dot(S, g.V * C);  // C symmetric: V C_i^T = V C_i
  } else {
    // The consistent divergence (physics_params.hpp) reads every neighbour's C (and s).
    if (phys.keeps_correction()) {
      const Mat<D> C = store_and_read(p.correction[i], correction_from_moments(used.M));
      if (phys.keeps_correction_shift()) p.correction_shift[i] = contract(C, e);
    }
    if (!heating) return;
    // Heating with eq. 8's V: it is what pairs with the conservative force of forces.hpp, so kinetic +
    // internal energy stay exactly conserved with it whichever gradient sets the stress (with the
    // consistent force, to the discretisation error).
    p.du_dt[i] = double_dot(S, g.V);
  }
}

// sums: scratch, the writable particles' gradient sums (kept for inspection).
// scales: scratch, the kernel scales (kernel_scales.hpp).
// scatter: scratch of the scatter density, summed on the same lists where the particles keep it
// (scatter_density.hpp).
template <int D, PairSource Pairs>
void compute_viscous_stress(Particles<D>& p, const Pairs& pairs, const PhysicsParams& phys, GradientSumsArray<D>& sums,
                            OverwriteVector<KernelScale>& scales, ScatterDensityScratch& scatter) {
  const std::size_t m = pairs.writable();
  const KernelScale* s = fill_kernel_scales(p, phys, scales, "velocity_gradient", particles_read_by(pairs));
  zero_sums(m, sums, phys.gradient_correction == GradientCorrection::Mixed);
  const auto gradient = sum_lists_into(sums, m, gradient_pair_terms(p, sums, m, phys, s));
  if (phys.keeps_scatter_density()) {
    const ScatterListData<D> sd = prepare_scatter_sums(p, m, phys, s, scatter);
    pairs.for_each_list(with_scatter_sums(gradient, sd), FactorUse::Read, "velocity_gradient", FarPairs::First);
    par::for_each(m, [&](std::size_t i) { settle_scatter_density(p, i, sd); }, "velocity_gradient");
  } else {
    pairs.for_each_list(gradient, FactorUse::Read, "velocity_gradient", FarPairs::First);
  }
  par::for_each(m, [&](std::size_t i) { settle_stress(p, i, sums[i], phys); }, "velocity_gradient");
}

// With the force correction on (moment_correction.hpp) the heating must use the gradient with the
// force's pair operator G_ij,
//   V^G_i = sum_j (m_j/rho_j) (v_j - v_i) (x) G_ij = (V C_i + sum_j (m_j/rho_j) (v_j - v_i) (x) C_j grad W) / 2,
// to keep kinetic + internal energy exactly conserved. The first half needs only particle i and is
// added in settle_stress; add_force_corrected_heating adds the second half, which needs
// p.correction of every neighbour: its sums H, each pair's two terms from corrected_heating_term
// (pair_terms.hpp).
template <int D, PairSource Pairs>
void sum_corrected_heating_terms(const Particles<D>& p, const Pairs& pairs, std::vector<Mat<D>>& H) {
  const std::size_t m = pairs.writable();
  sum_pair_lists(pairs, H, [&](std::uint32_t i, std::span<const std::uint32_t> js, std::span<const float> F, Mat<D>& sum_i) {
    const Vec<D> xi = p.pos[i], vi = p.vel[i];
    const Mat<D> Ci = as_double(p.correction[i]);
    const double Vi = p.volume[i];
    for (std::size_t q = 0; q < js.size(); ++q) {
      const std::uint32_t j = js[q];
      const Vec<D> dv = p.vel[j] - vi, dx = xi - p.pos[j];
      const double f = static_cast<double>(F[q]);
      accumulate(sum_i, corrected_heating_term(as_double(p.correction[j]), f, p.volume[j], dv, dx));
      if (j < m) accumulate(H[j], corrected_heating_term(Ci, f, Vi, dv, dx));
    }
  });
}

// The second half of the heating with the force correction; reads every neighbour's p.correction,
// so it runs after compute_viscous_stress has set them all (and the ghosts' have been refreshed).
// Not needed where the particles hold no energy rate (no energy equation: du_dt absent).
// H: scratch.
template <int D, PairSource Pairs>
void add_force_corrected_heating(Particles<D>& p, const Pairs& pairs, std::vector<Mat<D>>& H) {
  sum_corrected_heating_terms(p, pairs, H);
  const std::size_t m = pairs.writable();
  par::for_each(m, [&](std::size_t i) { p.du_dt[i] += 0.5 * double_dot(as_double(p.stress[i]), H[i]); }, "velocity_gradient");
}

}  // namespace sphdisk
