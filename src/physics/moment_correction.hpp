#pragma once
// Moment-corrected, pair-symmetrised kernel gradients for the viscous force (IAD0 of García-Senz,
// Cabezón & Escartín 2012; Rosswog 2015):
//   M_i,cb = -sum_j (m_j/rho_j) (x_i - x_j)_c (grad_i W_ij)_b,   C_i = M_i^-1,
//   G_ij   = (C_i + C_j) grad_i W_ij / 2,
// used in place of grad_i W_ij in eq. 6 and in the heating that pairs with it. Why: M is the
// identity only for a complete, regular sampling. On the ring's disordered particles the summation
// density carries the self term, the volumes m/rho come out too small and M < I; the velocity
// gradient is corrected for this (viscous_stress.hpp), but eq. 6's divergence of the stress carries
// the same factor, so the force, and the effective viscosity, stay too small. G_ij corrects the
// divergence to first order while keeping G_ji = -G_ij, so momentum and (with the matching heating)
// energy remain exactly conserved. C_i falls back to the identity where M_i is singular.
// Reads: pos, volume, pair factors. Writes: correction.
#include "core/particles.hpp"
#include "neighbours/neighbour_lists.hpp"
#include "parallel/loops.hpp"
#include "physics/pair_factors.hpp"

namespace sphdisk {

template <int D>
Mat<D> moment_matrix_at(std::size_t i, const Particles<D>& p, const NeighbourLists& nl, const PairFactors& F) {
  const Vec<D> xi = p.pos[i];
  Mat<D> M;
  for (std::size_t k = nl.offsets[i]; k < nl.offsets[i + 1]; ++k) {
    const std::uint32_t j = nl.index[k];
    const Vec<D> dx = xi - p.pos[j];
    const double f = p.volume[j] * static_cast<double>(F[k]);
    for (int a = 0; a < D; ++a)
      for (int b = 0; b < D; ++b) M(a, b) -= f * dx[a] * dx[b];
  }
  return M;
}

template <int D>
void compute_moment_corrections(Particles<D>& p, const NeighbourLists& nl, const PairFactors& F) {
  par::for_each(p.size(), [&](std::size_t i) {
    if (!invert_if_well_conditioned(moment_matrix_at(i, p, nl, F), p.correction[i])) p.correction[i] = identity<D>();
  }, "velocity_gradient");
}

// G_ij = (C_i + C_j) grad_i W_ij / 2.
template <int D>
Vec<D> corrected_pair_gradient(const Mat<D>& Ci, const Mat<D>& Cj, const Vec<D>& gradW) {
  return (contract(Ci, gradW) + contract(Cj, gradW)) * 0.5;
}

}  // namespace sphdisk
