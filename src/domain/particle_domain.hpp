#pragma once
// Where a process's particles live: the interface through which the rate evaluator and the
// integrators reach other processes without knowing how (MPI lives behind it, in
// distributed_domain.hpp). A single process needs no domain at all (RateEvaluator's default).
#include "core/particles.hpp"
#include "neighbours/cell_grid.hpp"

namespace sphdisk {

// Points in an evaluation after which ghost particles (copies of other processes' particles,
// stored after the owned ones) must get their owners' values before owned particles read them.
enum class GhostStage {
  SmoothingLength,  // h
  Density,          // rho, volume
  Stress,           // stress, correction
};

template <int D>
class ParticleDomain {
 public:
  virtual ~ParticleDomain() = default;
  // Appends ghosts: every other process's particle within `radius` of one of p's particles or whose
  // own 2 h reaches one. Returns the lattice of cells (shared by all processes, as a single process
  // would build it over all particles with cells >= min_cell_size).
  virtual Lattice<D> add_ghosts(Particles<D>& p, double min_cell_size, double radius) = 0;
  // Copies the owners' values of the stage's fields into the ghosts.
  virtual void refresh_ghosts(Particles<D>& p, GhostStage stage) = 0;
  // Removes the ghosts (p holds its owned particles again).
  virtual void remove_ghosts(Particles<D>& p) = 0;
  // Smallest / largest value over all processes (exact).
  virtual double min(double x) const = 0;
  virtual double max(double x) const = 0;
  // True on all processes when true on any.
  virtual bool any(bool x) const = 0;
};

}  // namespace sphdisk
