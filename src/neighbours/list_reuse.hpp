#pragma once
// Neighbour-list reuse with a skin (Verlet 1967): lists built with radii larger than the supports
// stay complete while the particles move relative to each other by less than the difference.
//
// Why relative motion: disc particles move fast (an orbit near the centre takes ~30 steps) but
// slowly against their neighbours, so the classical test on absolute displacement (rebuild when
// max |d_i| > skin / 2) would rebuild every step. The test here bounds the displacement *difference*
// of every pair that may now interact, cell by cell of the grid the lists were built on:
//   - d_i = x_i - x_i(build); per cell c: D_c = d of its first particle, e_c = max |d_i - D_c|,
//     B_c = bounding box of its particles now;
//   - any pair i in c, j in c' then has |d_i - d_j| <= e_c + e_c' + |D_c - D_c'|;
//   - a pair missing from i's list was >= listed_i apart at build time, so it is now
//     >= listed_i - (e_c + e_c' + |D_c - D_c'|) apart: beyond support_i while that bound stays
//     below slack_i = listed_i - support_i;
//   - the boxes of c and c' are now g apart, so only particles with support_i > g can have a
//     partner in the other cell within their support: the bound is held against the smallest
//     slack among those (a sparse particle's wide support reaching a dense cell is held against
//     its own slack, not the dense particles' narrow ones, which that distance cannot concern);
//   - cell pairs whose boxes are now >= the larger support apart hold no interacting pair at all,
//     so only cell pairs with boxes closer than that are tested (found through a grid of the
//     boxes' centres); no cell pair is left out however far the cells have moved.
// The lists are valid when every such cell pair passes. The test is sufficient, never an estimate;
// it is conservative by about the cells' size against the support.
//
// The lists' indices must still name the same particles: the particle order (IDs) is compared
// with the one at build time and any change (reordering, accretion) means a rebuild.
#include <cstdint>
#include <functional>
#include <vector>

#include "core/vec.hpp"
#include "neighbours/cell_grid.hpp"
#include "neighbours/neighbour_lists.hpp"

namespace sphdisk {

template <int D>
class ListReuse {
 public:
  // Radius of particle i (listed: a pair was put in i's list when closer than this at build time;
  // support: a pair interacts now when closer than this).
  using Radius = std::function<double(std::size_t)>;

  struct Verdict {
    bool valid = false;
    double used = 0;  // largest displacement bound / slack over the tested cell pairs (< 1: valid)
  };

  // Remembers the particle order and positions of a build on `grid` (whose cells group them).
  void record(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, const std::vector<std::uint64_t>& id);
  void forget() { id0_.clear(), pos0_.clear(), first_.clear(), recorded_ = false; }
  bool recorded() const { return recorded_; }
  // Whether the particles are the ones (in the same order) of the recorded build.
  bool same_particles(const std::vector<std::uint64_t>& id) const;
  // Whether lists built then (`grid` is the recorded build's) still hold every pair within the
  // supports now. Assumes same_particles().
  Verdict check(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, const Radius& listed, const Radius& support);

  std::size_t bytes() const;

 private:
  struct CellState {
    Vec<D> shift;       // D_c
    double spread = 0;  // e_c
    Vec<D> lo, hi;      // B_c
    double half_diagonal = 0;
    double slack = 0, support = 0;  // smallest slack, largest support of the cell's particles
    double narrowest = 0;           // smallest support of the cell's particles
  };
  struct Ranked {
    double support = 0, slack = 0;
  };
  double margin(std::size_t c, double apart) const;
  bool recorded_ = false;
  std::vector<std::uint64_t> id0_;
  std::vector<Vec<D>> pos0_;
  std::vector<std::uint32_t> first_;  // occupied cells of the build's grid: their first entries in grid.sorted, + end
  std::vector<CellState> cells_;      // state of each occupied cell now
  std::vector<Ranked> ranked_;        // per cell (slots of the build's grid): its particles' supports, widest first,
                                      // with the smallest slack among those as wide or wider
  std::vector<Vec<D>> centres_;       // of the boxes
  std::vector<std::uint64_t> centre_id_;
  std::vector<double> reach_;
  CellGrid<D> centre_grid_;
  NeighbourLists close_;              // cell pairs whose boxes may be closer than a support
};

}  // namespace sphdisk
