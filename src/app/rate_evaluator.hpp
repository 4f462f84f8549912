#pragma once
// One full evaluation of the time derivatives: cell list -> neighbour lists -> density -> velocity
// gradient and stress -> accelerations. The stages run in this order, each under its phase timer;
// this is the function the integrators call.
// Reads: pos, vel, mass, u, id. Writes: rho, stress, acc, du_dt; keeps the neighbour lists.
#include "core/particles.hpp"
#include "core/timers.hpp"
#include "neighbours/cell_grid.hpp"
#include "neighbours/neighbour_lists.hpp"
#include "physics/kernels.hpp"
#include "physics/pair_factors.hpp"
#include "physics/physics_params.hpp"

namespace sphdisk {

template <int D>
class RateEvaluator {
 public:
  RateEvaluator(KernelType kernel, double h, PhysicsParams phys, PhaseTimers& timers)
      : kernel_(kernel), h_(h), phys_(phys), timers_(timers) {}

  void evaluate(Particles<D>& p);

  double smoothing_length() const { return h_; }
  const PhysicsParams& physics() const { return phys_; }
  KernelType kernel() const { return kernel_; }
  PhaseTimers& timers() { return timers_; }
  const NeighbourLists& neighbours() const { return lists_; }
  const PairFactors& pair_factors() const { return factors_; }
  std::size_t evaluations() const { return evaluations_; }
  std::size_t pair_interactions() const { return pairs_; }  // summed over all evaluations

 private:
  KernelType kernel_;
  double h_;
  PhysicsParams phys_;
  PhaseTimers& timers_;
  CellGrid<D> grid_;       // kept between evaluations to reuse its memory
  NeighbourLists lists_;
  PairFactors factors_;    // kernel-gradient factor of every list entry (pair_factors.hpp)
  std::size_t evaluations_ = 0;
  std::size_t pairs_ = 0;
};

}  // namespace sphdisk
