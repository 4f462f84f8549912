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
#include "physics/moment_correction.hpp"
#include "physics/pair_factors.hpp"
#include "physics/physics_params.hpp"

namespace sphdisk {

// Eq. 8's sum V together with the moment matrix M_cb = -sum_j (m_j/rho_j) (W_,b / dx_b) dx_c dx_b of
// the same neighbours, in one pass. For a linear field v = G x, V = G M exactly.
template <int D>
struct GradientSums {
  Mat<D> V, M;
};

template <int D>
GradientSums<D> gradient_sums_at(std::size_t i, const Particles<D>& p, const NeighbourLists& nl, const PairFactors& F) {
  const Vec<D> xi = p.pos[i], vi = p.vel[i];
  GradientSums<D> g;
  for (std::size_t k = nl.offsets[i]; k < nl.offsets[i + 1]; ++k) {
    const std::uint32_t j = nl.index[k];
    const Vec<D> dx = xi - p.pos[j];
    const double f = p.volume[j] * static_cast<double>(F[k]);  // (m_j / rho_j) W_,b / dx_b
    const Vec<D> dv = p.vel[j] - vi;
    for (int a = 0; a < D; ++a)
      for (int b = 0; b < D; ++b) {
        g.V(a, b) += f * dv[a] * dx[b];
        g.M(a, b) -= f * dx[a] * dx[b];
      }
  }
  return g;
}

template <int D>
Mat<D> velocity_gradient_at(std::size_t i, const Particles<D>& p, const NeighbourLists& nl, const PairFactors& F) {
  return gradient_sums_at(i, p, nl, F).V;
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

template <int D>
Mat<D> kinematic_stress(const Mat<D>& V, const PhysicsParams& phys) {
  const double div = V.trace();
  Mat<D> S;
  for (int a = 0; a < D; ++a)
    for (int b = 0; b < D; ++b) S(a, b) = phys.nu * (V(a, b) + V(b, a));
  for (int a = 0; a < D; ++a) S(a, a) += (phys.nu_bulk - 2.0 / 3.0 * phys.nu) * div;
  return S;
}

// With the force correction on (moment_correction.hpp) the heating must use the gradient with the
// force's pair operator G_ij,
//   V^G_i = sum_j (m_j/rho_j) (v_j - v_i) (x) G_ij = (V C_i + sum_j (m_j/rho_j) (v_j - v_i) (x) C_j grad W) / 2,
// to keep kinetic + internal energy exactly conserved. The first half needs only particle i and is
// added in the first pass; this is the second half, which needs p.correction of every neighbour.
template <int D>
Mat<D> neighbour_corrected_gradient_at(std::size_t i, const Particles<D>& p, const NeighbourLists& nl,
                                       const PairFactors& F) {
  const Vec<D> xi = p.pos[i], vi = p.vel[i];
  Mat<D> H;
  for (std::size_t k = nl.offsets[i]; k < nl.offsets[i + 1]; ++k) {
    const std::uint32_t j = nl.index[k];
    const Vec<D> g = contract(p.correction[j], (xi - p.pos[j]) * (p.volume[j] * static_cast<double>(F[k])));
    const Vec<D> dv = p.vel[j] - vi;
    for (int a = 0; a < D; ++a)
      for (int b = 0; b < D; ++b) H(a, b) += dv[a] * g[b];
  }
  return H;
}

template <int D>
void compute_viscous_stress(Particles<D>& p, const NeighbourLists& nl, const PairFactors& F, const PhysicsParams& phys) {
  par::for_each(nl.size(), [&](std::size_t i) {  // the particles with lists (density.hpp)
    const GradientSums<D> g = gradient_sums_at(i, p, nl, F);
    p.stress[i] = kinematic_stress(phys.gradient_correction ? corrected_gradient(g) : g.V, phys);
    if (phys.force_correction) {
      p.correction[i] = correction_from_moments(g.M);
      p.du_dt[i] = 0.5 * double_dot(p.stress[i], g.V * p.correction[i]);  // C symmetric: V C_i^T = V C_i
    } else {
      // Heating with eq. 8's V: it is what pairs with the force of forces.hpp, so kinetic + internal
      // energy stay exactly conserved whichever gradient sets the stress.
      p.du_dt[i] = double_dot(p.stress[i], g.V);
    }
  }, "velocity_gradient");
}

// The second half of the heating with the force correction (see neighbour_corrected_gradient_at);
// reads every neighbour's p.correction, so it runs after compute_viscous_stress has set them all.
template <int D>
void add_force_corrected_heating(Particles<D>& p, const NeighbourLists& nl, const PairFactors& F) {
  par::for_each(nl.size(), [&](std::size_t i) {  // the particles with lists (density.hpp)
    p.du_dt[i] += 0.5 * double_dot(p.stress[i], neighbour_corrected_gradient_at(i, p, nl, F));
  }, "velocity_gradient");
}

}  // namespace sphdisk
