#pragma once
// Interaction lists for variable smoothing lengths. With a kernel gradient averaged over the pair,
//   grad W_ij = (grad W(r_ij, h_i) + grad W(r_ij, h_j)) / 2      (Hernquist & Katz 1989),
// i and j interact when |x_i - x_j| < 2 max(h_i, h_j): through i's own support (gather) or through
// the larger support of j (scatter). The relation is symmetric, so every pair sum built on these
// lists keeps its i <-> j antisymmetry and with it momentum conservation.
// Input: gather lists in which i's list holds exactly the j with |x_i - x_j| < 2 h_i (as
// build_settled_neighbour_lists returns them). Output order, fixed for any thread count: first i's
// gather neighbours in their order, then the scatter-only neighbours by particle ID.
#include <cstdint>
#include <vector>

#include "core/vec.hpp"
#include "neighbours/neighbour_lists.hpp"

namespace sphdisk {

template <int D>
void build_interaction_lists(const NeighbourLists& gather, const std::vector<Vec<D>>& pos,
                             const std::vector<double>& h, const std::vector<std::uint64_t>& id, NeighbourLists& out);

}  // namespace sphdisk
