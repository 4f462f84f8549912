#pragma once
// What the integrators need of the rate evaluation (evaluate/rate_evaluator.hpp implements it), so that
// integrate/ depends on this and not on the evaluator's search, lists and halo machinery.
#include <cstddef>
#include <cstdint>
#include <span>

#include "core/particles.hpp"
#include "parallel/timers.hpp"
#include "physics/physics_params.hpp"

namespace sphdisk {

template <int D>
class RateSource {
 public:
  virtual ~RateSource() = default;
  // New h, rho, stress, acc and du_dt for the first `active` particles; the others count as
  // neighbours with their values (block timesteps' partial evaluations).
  virtual void evaluate(Particles<D>& p, std::size_t active) = 0;
  void evaluate(Particles<D>& p) { evaluate(p, p.size()); }
  // The same first `active` particles again at the positions of the last evaluation, with other
  // velocities (super-step stages, integrate/super_steps.hpp). moved: the first moved.size()
  // particles were renumbered since that evaluation, particle k being the one that was moved[k]
  // (empty: none was).
  virtual void evaluate_again(Particles<D>& p, std::size_t active, std::span<const std::uint32_t> moved) = 0;
  // Smallest / largest over all processes (exact: the same on every rank).
  virtual double global_min(double x) const = 0;
  virtual double global_max(double x) const = 0;
  // Whether acc includes the point mass's gravity or only the hydrodynamic part (an integrator
  // that substeps gravity itself).
  virtual void include_gravity(bool yes) = 0;
  virtual const PhysicsParams& physics() const = 0;
  virtual PhaseTimers& timers() = 0;
};

}  // namespace sphdisk
