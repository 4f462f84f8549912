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

namespace sphdisk {

using PairFactors = std::vector<float>;  // indexed like NeighbourLists::index

}  // namespace sphdisk
