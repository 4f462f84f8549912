#pragma once
// The "tuned sequential variant" of the paper's Fig. 4 comparison (P98 sec. 4.1): each pair is
// visited once (half neighbour lists, j after i in cell order) and its contribution is added to
// both particles. It cannot run in parallel without write conflicts, which is why the parallel
// code keeps full lists; this variant measures what that choice costs.
#include "evaluate/rate_evaluator.hpp"
#include "neighbours/cell_grid.hpp"

namespace sphdisk::bench {

struct SymmetricSequential {
  CellGrid<2> grid;
  NeighbourLists half;  // pairs (i, j) with j after i in cell order, each once
  PairFactors factors;  // kernel-gradient factor per pair
  // Cell build, half-list search, density, velocity gradient/stress and accelerations, serially.
  void evaluate(Particles<2>& p, double h, const PhysicsParams& phys);
};

}  // namespace sphdisk::bench
