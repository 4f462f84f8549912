#include "app/rate_evaluator.hpp"

#include "neighbours/cell_grid.hpp"
#include "physics/density.hpp"
#include "physics/forces.hpp"
#include "physics/viscous_stress.hpp"

namespace sphdisk {

template <int D>
void RateEvaluator<D>::evaluate(Particles<D>& p) {
  const double support = 2.0 * h_;  // all kernels have compact support 2h
  {
    ScopedPhase t(timers_, "cell_build");
    build_cell_grid(p.pos, p.id, 0.5 * support, grid_);
  }
  {
    ScopedPhase t(timers_, "neighbour_search");
    build_neighbour_lists(grid_, p.pos, support, lists_);
  }
  {
    ScopedPhase t(timers_, "density");
    with_kernel(kernel_, [&](auto k) { compute_density(p, lists_, KernelAt<decltype(k), D>(h_), factors_); });
  }
  {
    ScopedPhase t(timers_, "velocity_gradient");
    compute_viscous_stress(p, lists_, factors_, phys_);
  }
  {
    ScopedPhase t(timers_, "forces");
    compute_accelerations(p, lists_, factors_, phys_);
  }
  ++evaluations_;
  pairs_ += lists_.total();
}

template class RateEvaluator<2>;
template class RateEvaluator<3>;

}  // namespace sphdisk
