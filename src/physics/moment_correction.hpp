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
// energy remain exactly conserved. C_i falls back to the identity where M_i is singular. G_ij is
// formed per pair by corrected_pair_gradient (pair_terms.hpp).
#include "core/vec.hpp"

namespace sphdisk {

// C_i = M_i^-1, or the identity where M_i is singular. M comes from the gradient pair terms
// (list_sums.hpp, add_gradient_list), summed with the velocity gradient in one pass.
template <int D>
Mat<D> correction_from_moments(const Mat<D>& M) {
  Mat<D> C;
  return invert_if_well_conditioned(M, C) ? C : identity<D>();
}

}  // namespace sphdisk
