#pragma once
// Velocity gradient, shear and viscous stress of each particle (P98 eqs. 2, 7, 8).
//   V_ab,i     = sum_j (m_j / rho_j) (v_a,j - v_a,i) W_,b           (eq. 8, W_,b = d W_ij / d x_i,b)
//   sigma_ab,i = V_ab,i + V_ba,i - (2/3) delta_ab V_gg,i             (eq. 7; 2/3 also in 2D, physics.md 1)
//   S_i        = t_i / rho_i = nu sigma_i + nu_bulk delta tr(V_i)    (eq. 2 divided by rho)
// Storing the kinematic stress S = t / rho lets the force loop use eq. 6 as written:
//   m_j (nu_j sigma_j / rho_i + nu_i sigma_i / rho_j) = m_j (S_j / rho_i + S_i / rho_j).
// Viscous heating du_i/dt = S_i : V_i (physics.md sec. 2: sigma:V, not sigma:sigma/2) makes the
// kinetic + internal energy exactly conserved together with the force of forces.hpp.
// Reads: pos, vel, volume, pair factors. Writes: stress, du_dt (viscous heating part).
#include "core/particles.hpp"
#include "neighbours/neighbour_lists.hpp"
#include "parallel/loops.hpp"
#include "physics/pair_factors.hpp"
#include "physics/physics_params.hpp"

namespace sphdisk {

template <int D>
Mat<D> velocity_gradient_at(std::size_t i, const Particles<D>& p, const NeighbourLists& nl, const PairFactors& F) {
  const Vec<D> xi = p.pos[i], vi = p.vel[i];
  Mat<D> V;
  for (std::size_t k = nl.offsets[i]; k < nl.offsets[i + 1]; ++k) {
    const std::uint32_t j = nl.index[k];
    const Vec<D> dx = xi - p.pos[j];
    const double f = p.volume[j] * static_cast<double>(F[k]);  // (m_j / rho_j) W_,b / dx_b
    const Vec<D> dv = p.vel[j] - vi;
    for (int a = 0; a < D; ++a)
      for (int b = 0; b < D; ++b) V(a, b) += f * dv[a] * dx[b];
  }
  return V;
}

template <int D>
Mat<D> kinematic_stress(const Mat<D>& V, const PhysicsParams& phys) {
  const double div = V.trace();
  Mat<D> S;
  for (int a = 0; a < D; ++a)
    for (int b = 0; b < D; ++b) S(a, b) = phys.nu * (V(a, b) + V(b, a));
  for (int a = 0; a < D; ++a) S(a, a) += (phys.nu_bulk - 2.0 / 3.0 * phys.nu) * div;
  return S;
}

template <int D>
void compute_viscous_stress(Particles<D>& p, const NeighbourLists& nl, const PairFactors& F, const PhysicsParams& phys) {
  par::for_each(p.size(), [&](std::size_t i) {
    const Mat<D> V = velocity_gradient_at(i, p, nl, F);
    p.stress[i] = kinematic_stress(V, phys);
    p.du_dt[i] = double_dot(p.stress[i], V);
  }, "velocity_gradient");
}

}  // namespace sphdisk
