#pragma once
// Hydrodynamic accelerations from the stored stresses (P98 eqs. 1, 6, 9) plus point-mass gravity.
//   viscous:  a_i += sum_j m_j (S_i / rho_j + S_j / rho_i) . grad_i W_ij                (eq. 6)
//   pressure: a_i -= sum_j m_j (P_i / rho_i^2 + P_j / rho_j^2) grad_i W_ij           (physics.md 2)
//             du_i/dt += (P_i / rho_i^2) sum_j m_j (v_i - v_j) . grad_i W_ij
//   gravity:  a_i -= G M x_i / |x_i|^3   (left out when the integrator substeps it)
// With phys.force_correction, grad_i W_ij is replaced by G_ij of moment_correction.hpp.
// Pair terms are antisymmetric in i <-> j, so linear momentum is conserved to round-off. Angular
// momentum is not exactly conserved (the viscous pair force is not along r_ij; physics.md 2).
// The viscous sum is evaluated factored, with no division in the pair loop:
//   sum_j m_j (S_i/rho_j + S_j/rho_i) g_j = S_i . sum_j (m_j/rho_j) g_j + (1/rho_i) sum_j m_j S_j . g_j.
// Reads: pos, vel, mass, rho, volume, stress, pair factors, du_dt (heating from viscous_stress.hpp).
// Writes: acc, du_dt.
#include <cmath>

#include "core/particles.hpp"
#include "neighbours/neighbour_lists.hpp"
#include "parallel/loops.hpp"
#include "physics/moment_correction.hpp"
#include "physics/pair_factors.hpp"
#include "physics/physics_params.hpp"

namespace sphdisk {

template <int D>
Vec<D> point_mass_gravity(const Vec<D>& x, double gm) {
  const double r2 = norm2(x);
  const double r = std::sqrt(r2);
  return x * (-gm / (r2 * r));
}

template <int D>
Vec<D> hydro_acceleration_at(std::size_t i, const Particles<D>& p, const NeighbourLists& nl, const PairFactors& F,
                             const PhysicsParams& phys, double& du_dt_pressure) {
  const Vec<D> xi = p.pos[i], vi = p.vel[i];
  const double inv_rho_i = 1.0 / p.rho[i];
  const Mat<D>& Si = p.stress[i];
  const bool with_pressure = phys.eos != EquationOfState::None;
  const double Pi_rho2 = with_pressure ? pressure(phys, p.rho[i]) * inv_rho_i * inv_rho_i : 0.0;
  Vec<D> vol_grad, stress_grad, a_pressure;  // sum (m_j/rho_j) g, sum m_j S_j . g
  double work = 0.0;
  for (std::size_t k = nl.offsets[i]; k < nl.offsets[i + 1]; ++k) {
    const std::uint32_t j = nl.index[k];
    Vec<D> gradW = (xi - p.pos[j]) * static_cast<double>(F[k]);
    if (phys.force_correction) gradW = corrected_pair_gradient(p.correction[i], p.correction[j], gradW);
    const double mj = p.mass[j];
    vol_grad += gradW * p.volume[j];
    stress_grad += contract(p.stress[j], gradW) * mj;
    if (with_pressure) {
      const double rho_j = p.rho[j];
      const double Pj_rho2 = pressure(phys, rho_j) / (rho_j * rho_j);
      a_pressure -= gradW * (mj * (Pi_rho2 + Pj_rho2));
      work += mj * dot(vi - p.vel[j], gradW);
    }
  }
  du_dt_pressure = Pi_rho2 * work;
  return contract(Si, vol_grad) + stress_grad * inv_rho_i + a_pressure;
}

template <int D>
void compute_accelerations(Particles<D>& p, const NeighbourLists& nl, const PairFactors& F, const PhysicsParams& phys,
                           bool with_gravity = true) {
  par::for_each(nl.size(), [&](std::size_t i) {  // the particles with lists (density.hpp)
    double du_pressure = 0.0;
    p.acc[i] = hydro_acceleration_at(i, p, nl, F, phys, du_pressure);
    if (with_gravity) p.acc[i] += point_mass_gravity(p.pos[i], phys.gm);
    p.du_dt[i] += du_pressure;
  }, "forces");
}

}  // namespace sphdisk
