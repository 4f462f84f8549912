#pragma once
// Kernel-gradient factors F_ij = (1/r) dW/dr of every neighbour-list entry, so that
// grad_i W_ij = (x_i - x_j) F_ij. They are computed once per rate evaluation (in the density loop,
// where r is known anyway) and read by the velocity-gradient and force loops, which then need no
// square root, division or kernel evaluation. Stored in single precision (as the paper notes,
// single precision halves the memory; accumulation stays double). F_ij and F_ji come from the same
// r and are bitwise equal, so momentum and energy conservation stay exact. Without stored lists
// (neighbours/pair_scan.hpp) each loop computes them again from r and rounds them to single
// precision the same way, so every loop still sees the same factor of a pair.
#include <vector>

#include "core/overwrite_vector.hpp"
#include "physics/kernels.hpp"

namespace sphdisk {

using PairFactors = OverwriteVector<float>;  // indexed like NeighbourLists::index (every factor formed before it is read)

// What the pair-averaged kernel gradient needs of a particle's kernel: 1/h and sigma_D / h^(D+1),
// 16 bytes gathered per pair (a whole KernelAt is 40).
struct KernelSlope {
  double inv_h = 0, dw_norm = 0;
};

template <class K, int D>
KernelSlope slope_of(const KernelAt<K, D>& k) {
  return {k.inv_h, k.w_norm * k.inv_h};  // dW/dr = dw_norm w'(r / h), as KernelAt::dW_dr
}

// What a pair's kernel value needs of a particle's kernel: 1/h and sigma_D / h^D.
struct KernelScale {
  double inv_h = 0, w_norm = 0;
};

// A pair's kernel values with either particle's smoothing length.
struct PairValues {
  double i = 0, j = 0;
};

template <class K, int D>
KernelScale scale_of(const KernelAt<K, D>& k) {
  return {k.inv_h, k.w_norm};
}

// The pair's two kernel values W(r, h_i) and W(r, h_j) (W(r, h) = sigma_D / h^D w(r / h)).
template <class K>
PairValues pair_kernel_values(const KernelScale& si, const KernelScale& sj, double r) {
  return {si.w_norm * K::w(r * si.inv_h), sj.w_norm * K::w(r * sj.inv_h)};
}

// The pair-averaged kernel value (W(r, h_i) + W(r, h_j)) / 2, the value whose gradient
// pair_average_factor gives (the mixed correction's W_ij, physics_params.hpp).
inline double pair_average_value(const PairValues& w) { return 0.5 * (w.i + w.j); }

// The kernel-gradient factor of a pair with variable h: (dW_i/dr + dW_j/dr) / (2 r), one division;
// w'(0) = 0, so coincident particles get 0 (divided by 2 instead of 0: no branch, so that the loops
// forming a list's factors vectorise).
template <class K>
double pair_average_factor(const KernelSlope& si, const KernelSlope& sj, double r) {
  return (si.dw_norm * K::dw(r * si.inv_h) + sj.dw_norm * K::dw(r * sj.inv_h)) / (2.0 * (r > 0 ? r : 1.0));
}

}  // namespace sphdisk
