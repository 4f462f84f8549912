#pragma once
// Where a process's particles live: the interface through which the rate evaluator and the
// integrators reach other processes without knowing how (MPI lives behind it, in
// distributed_domain.hpp). A single process needs no domain at all (RateEvaluator's default).
#include <cstdint>
#include <functional>
#include <vector>

#include "core/particles.hpp"
#include "neighbours/cell_grid.hpp"

namespace sphdisk {

// Points in an evaluation after which ghost particles (copies of other processes' particles,
// stored after the owned ones) must get their owners' values before owned particles read them;
// the fields each carries are flagged in the field table (core/particles.hpp: kHaloSmoothingLength,
// kHaloDensity, kHaloStress).
enum class GhostStage {
  SmoothingLength,
  Density,
  Stress,
};

// A radius per particle (by index).
using RadiusOf = std::function<double(std::size_t)>;

template <int D>
class ParticleDomain {
 public:
  virtual ~ParticleDomain() = default;
  // Appends ghosts: every other process's particle j within need(i) of one of p's particles i, or
  // within its own reach(j) of one (need: the neighbour-search radius; reach: the particle's own
  // support 2 h_j, for pairs that only j's kernel covers). Radii are of owned particles; a particle
  // with need(i) < 0 reads no ghosts (not written in this evaluation) and draws none. Returns
  // the lattice of cells (shared by all processes: as a single process would build it over all
  // particles with cells >= min_cell_size).
  virtual Lattice<D> add_ghosts(Particles<D>& p, double min_cell_size, const RadiusOf& need, const RadiusOf& reach) = 0;
  // Copies the owners' values of the stage's fields into the ghosts.
  virtual void refresh_ghosts(Particles<D>& p, GhostStage stage) = 0;
  // Removes the ghosts (p holds its owned particles again).
  virtual void remove_ghosts(Particles<D>& p) = 0;
  // Smallest / largest value over all processes (exact).
  virtual double min(double x) const = 0;
  virtual double max(double x) const = 0;
  virtual std::uint64_t sum(std::uint64_t x) const = 0;
  // The k-th smallest (from 0) of all processes' non-negative values, exactly.
  virtual double kth_smallest(const std::vector<double>& values, std::uint64_t k) const = 0;
  // True on all processes when true on any.
  virtual bool any(bool x) const = 0;
};

}  // namespace sphdisk
