#pragma once
// The halo of ghost particles a rank needs for its owned particles' neighbour sums. Ghosts are
// copies of other ranks' particles, appended after the owned ones ([0, owned) owned, [owned, size)
// ghosts). They are chosen by their owners: particle j goes to rank R when it lies within
// radius(j), or within R's own need there, of a top cell in which R has particles that read ghosts
// (R's list of such cells, sent to the ranks within reach of them: domain/rank_boxes.hpp), so
// particles that drifted out of their rank's top cells during a step are still served. Rates
// computed for ghosts are incomplete and are overwritten by refresh() with the owners' values
// before any owned particle reads them.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "core/particles.hpp"
#include "domain/decomposition.hpp"
#include "parallel/communicator.hpp"

namespace sphdisk {

template <int D>
class Halo {
 public:
  // Appends the ghosts: every other rank's particle j that lies within need(i) of a particle i of
  // this rank, or within reach(j) of one (radii of owned particles; found through the top cells of
  // `grid`, so some spare ghosts come along); particles with need(i) < 0 draw none. p must hold
  // owned particles only. Ghosts arrive without the fields flagged kHaloDensity or kHaloStress,
  // which refresh() brings before any pair loop reads them, or kOwnerOnly.
  void build(const Communicator& comm, const Decomposition<D>& grid, Particles<D>& p,
             const std::function<double(std::size_t)>& need, const std::function<double(std::size_t)>& reach);
  // Copies the owners' current values of the fields flagged halo_flag (kHaloSmoothingLength,
  // kHaloDensity or kHaloStress, core/particles.hpp) into the ghosts (same ghosts as build()).
  void refresh(const Communicator& comm, Particles<D>& p, unsigned halo_flag) const;
  // Removes the ghosts.
  void drop(Particles<D>& p) const { p.resize(owned_); }

  std::size_t owned() const { return owned_; }
  std::size_t ghosts() const { return ghosts_; }

 private:
  std::vector<std::vector<std::uint32_t>> send_;  // per rank: owned particles sent as ghosts
  std::size_t owned_ = 0, ghosts_ = 0;
};

}  // namespace sphdisk
