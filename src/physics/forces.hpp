#pragma once
// Hydrodynamic accelerations from the stored stresses (P98 eqs. 1, 6, 9) plus point-mass gravity.
//   viscous:  a_i += sum_j m_j (S_i / rho_j + S_j / rho_i) . grad_i W_ij                (eq. 6)
//             or, by default, its consistent form (physics_params.hpp, ViscousForce):
//             a_i += sum_j V_j [S_j - S_i + S_i ln(rho_j / rho_i)] . C_i grad_i W_ij
//   pressure: a_i -= sum_j m_j (P_i / rho_i^2 + P_j / rho_j^2) grad_i W_ij           (docs/physics.md sec. 2)
//             du_i/dt += (P_i / rho_i^2) sum_j m_j (v_i - v_j) . grad_i W_ij
//   artificial viscosity (physics.av_alpha > 0, with pressure): q_i / rho_i^2 added to P_i / rho_i^2
//             for approaching pairs (pair_terms.hpp, artificial_viscosity_pair), and each
//             particle's signal speed for the step limit
//   gravity:  a_i -= G M x_i / |x_i|^3   (left out when the integrator substeps it)
// With phys.force_correction, grad_i W_ij is replaced by G_ij of moment_correction.hpp. Each pair's
// terms are those of pair_terms.hpp (summed by list_sums.hpp).
// The conservative form's pair terms are antisymmetric in i <-> j, so linear momentum is conserved
// to round-off (the consistent form's to the discretisation error). Angular momentum is not
// exactly conserved (the viscous pair force is not along r_ij; docs/physics.md sec. 2).
// Reads: pos, vel, mass, rho (or the scatter density: PairDensity::Scatter), volume, stress, pair
// factors, du_dt (heating from viscous_stress.hpp).
// Writes: acc, du_dt (the pressure work, where the particles hold it: with an energy equation).
#include <cmath>
#include <vector>

#include "core/pair_source.hpp"
#include "core/particles.hpp"
#include "core/snug_resize.hpp"
#include "parallel/loops.hpp"
#include "physics/list_sums.hpp"
#include "physics/moment_correction.hpp"
#include "physics/kernel_scales.hpp"
#include "physics/pair_factors.hpp"
#include "physics/physics_params.hpp"

namespace sphdisk {

template <int D>
Vec<D> point_mass_gravity(const Vec<D>& x, double gm) {
  const double r2 = norm2(x);
  const double r = std::sqrt(r2);
  return gm == 0 ? Vec<D>{} : x * (-gm / (r2 * r));  // (no point mass: a blast wave's centre may be empty)
}

// Per-particle factors of the pair terms, for every particle the pairs read (ghosts included).
struct ForceScratch {
  OverwriteVector<double> inv_rho, p_over_rho2;  // 1 / rho (empty where only the consistent divergence reads
                                                 // the density); P / rho^2 (empty without pressure)
  OverwriteVector<double> log_rho;               // ln rho (empty without the consistent divergence)
  OverwriteVector<double> rho_without_self;      // rho - m W(0, h) (empty but with PairDensity::Others)
  OverwriteVector<KernelScale> scales;           // kernel scales (empty but where pairs need W_ij)
  OverwriteVector<double> sound_speed;           // c_s (empty without artificial viscosity)
};

// Each pair is visited once (pair_lists.hpp) and gives both particles their terms:
//   a_i += m_j X . g,  a_j -= m_i X . g,   X = S_i / rho_j + S_j / rho_i - (P_i/rho_i^2 + P_j/rho_j^2) I,
// with g = grad_i W_ij = -grad_j W_ij (or G_ij), and the pressure work (P/rho^2) m (v_i - v_j) . g
// for both, as (v_j - v_i) . grad_j W = (v_i - v_j) . g.
// Before the pair terms: the per-particle factors of the particles the pair loops read (reads(i):
// particles_read_by, pair_source.hpp; the others' are left unset) and the writable particles'
// accelerations set to gravity (or zero); returns what the list loop reads.
template <int D, class Reads = bool (*)(std::size_t)>
ForceListData<D> prepare_forces(Particles<D>& p, std::size_t m, const PhysicsParams& phys, ForceScratch& scratch,
                                bool with_gravity, Reads reads = [](std::size_t) { return true; }) {
  const bool with_pressure = phys.eos != EquationOfState::None;
  const bool consistent = phys.viscous_force == ViscousForce::Consistent;
  // The consistent divergence reads the volumes m / rho the density stage set (p.volume), not 1 / rho.
  const bool reads_inv_rho = !consistent || with_pressure;
  auto& inv_rho = scratch.inv_rho;
  auto& Pr = scratch.p_over_rho2;
  renew_snug(inv_rho, reads_inv_rho ? p.size() : 0);
  renew_snug(Pr, with_pressure ? p.size() : 0);  // (read only with pressure, list_sums.hpp)
  auto& log_rho = scratch.log_rho;
  renew_snug(log_rho, consistent ? p.size() : 0);
  const bool others = consistent && phys.pair_density == PairDensity::Others;
  const bool scatter = phys.keeps_scatter_density();  // ln rho_s (scatter_density.hpp)
  auto& rho_without_self = scratch.rho_without_self;
  renew_snug(rho_without_self, others ? p.size() : 0);
  const KernelScale* scales = fill_kernel_scales(p, phys, scratch.scales, "forces", reads);
  const double w0 = with_kernel(phys.kernel, [](auto k) { return KernelAt<decltype(k), D>(1.0).W(0.0); });
  const bool av = with_pressure && phys.artificial_viscosity();
  renew_snug(scratch.sound_speed, av ? p.size() : 0);
  par::for_each(p.size(), [&](std::size_t i) {
    if (i >= m && !reads(i)) return;
    if (reads_inv_rho) inv_rho[i] = 1.0 / p.rho[i];
    if (consistent) log_rho[i] = std::log(scatter ? p.scatter_density[i] : static_cast<double>(p.rho[i]));
    if (others) rho_without_self[i] = static_cast<double>(p.rho[i]) - p.mass[i] * w0 / std::pow(p.h[i], D);
    const double u = p.u.empty() ? 0.0 : p.u[i];
    if (with_pressure) Pr[i] = pressure(phys, static_cast<double>(p.rho[i]), p.pos[i], u) * inv_rho[i] * inv_rho[i];
    if (av) {
      scratch.sound_speed[i] = sound_speed_at(phys, p.pos[i], u);
      if (i < m) p.signal_speed[i] = scratch.sound_speed[i];  // raised by the pairs (timestep.hpp)
    }
    if (i < m) p.acc[i] = with_gravity ? point_mass_gravity(p.pos[i], phys.gm) : Vec<D>{};
  }, "forces");
  return ForceListData<D>{p.pos.data(), p.vel.data(), p.stress.data(), p.correction.data(), p.mass.data(),
                          reads_inv_rho ? inv_rho.data() : nullptr, Pr.data(), p.acc.data(), p.du_dt.empty() ? nullptr : p.du_dt.data(), m, with_pressure,
                          phys.force_correction, consistent ? log_rho.data() : nullptr, consistent,
                          others ? rho_without_self.data() : nullptr,
                          phys.keeps_correction_shift() ? p.correction_shift.data() : nullptr, scales, phys.kernel,
                          av ? scratch.sound_speed.data() : nullptr, av && phys.av_limiter ? p.av_limiter.data() : nullptr,
                          av ? p.av_alpha.data() : nullptr, phys.av_beta, av ? p.signal_speed.data() : nullptr,
                          consistent ? p.volume.data() : nullptr};
}

// The list loop's body: f(i, js, F) of Pairs::for_each_list.
template <int D>
auto force_list_body(Particles<D>& p, const ForceListData<D>& d) {
  return [&p, d](std::uint32_t i, std::span<const std::uint32_t> js, std::span<float> F) {
    Vec<D> ai;
    double du_i = 0.0;
    add_force_list(d, i, js, std::span<const float>(F), ai, du_i);  // list_sums.hpp
    if (i < d.writable) {
      p.acc[i] += ai;
      if (d.du_dt) p.du_dt[i] += du_i;
    }
  };
}

template <int D, PairSource Pairs>
void compute_accelerations(Particles<D>& p, const Pairs& pairs, const PhysicsParams& phys, ForceScratch& scratch,
                           bool with_gravity = true) {
  const ForceListData<D> d = prepare_forces(p, pairs.writable(), phys, scratch, with_gravity, particles_read_by(pairs));
  pairs.for_each_list(force_list_body(p, d), FactorUse::Read, "forces");
}

}  // namespace sphdisk
