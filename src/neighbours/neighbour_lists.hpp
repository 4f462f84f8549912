#pragma once
// Per-particle neighbour lists (P98 sec. 4.1, Fig. 2) stored as offsets + indices (CSR). Particle i
// has neighbours index[offsets[i] .. offsets[i+1]), itself excluded, all j with |x_i - x_j| < radius,
// in cell order (by x, then ID, inside a cell: see cell_grid.hpp): a fixed order, so pair sums give
// the same bits for any thread count.
#include <cstdint>
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "core/overwrite_vector.hpp"
#include "core/vec.hpp"
#include "neighbours/cell_grid.hpp"

namespace sphdisk {

struct NeighbourLists {
  static constexpr std::size_t kBlock = 512;  // particles per work unit of the builders
  std::vector<std::size_t> offsets;    // size n + 1
  OverwriteVector<std::uint32_t> index;  // the lists, once joined

  std::size_t size() const { return offsets.empty() ? 0 : offsets.size() - 1; }
  std::size_t count(std::size_t i) const { return offsets[i + 1] - offsets[i]; }
  std::size_t total() const { return offsets.empty() ? 0 : offsets.back(); }

  // Builder scratch, one buffer per block of kBlock particles, kept between builds so that
  // rebuilding reuses memory instead of faulting in fresh pages (which serialises threads in the
  // kernel). A block's lists are the first entries of its buffer, one after the other.
  std::vector<std::vector<std::uint32_t>> block_index, block_count;
  // false: the lists are still in the blocks (index is not filled; begin/end may not be used).
  // A reader that visits each list once (the half lists, pair_lists.hpp) reads them there through
  // list(i), which spares the copy of every entry into index.
  bool joined = true;
  // Or the lists lie inside another set of lists, `within`, which must outlive the reads: list i is
  // count(i) entries from start[i] on (half lists left inside the gather lists they were made from,
  // pair_lists.cpp). within is null where the lists are held here.
  const NeighbourLists* within = nullptr;
  std::vector<const std::uint32_t*> start;
  // Or they lie in block buffers of any size, one per tile of a pair schedule (tile_half_lists.hpp),
  // list i at start[i] as with `within`; not joined.
  bool tiled = false;

  std::span<const std::uint32_t> list(std::size_t i) const {
    if (within || tiled) return {start[i], count(i)};
    if (joined) return {index.data() + offsets[i], count(i)};
    const std::size_t b = i / kBlock;
    return {block_index[b].data() + (offsets[i] - offsets[b * kBlock]), count(i)};
  }
  // List i for writing in place (lists held here).
  std::span<std::uint32_t> entries(std::size_t i) {
    const std::span<const std::uint32_t> l = list(i);
    return {const_cast<std::uint32_t*>(l.data()), l.size()};
  }
  const std::uint32_t* begin(std::size_t i) const { return list(i).data(); }  // joined or not
  const std::uint32_t* end(std::size_t i) const { return begin(i) + count(i); }
  // The offsets of n lists left in the blocks (block b's counts: block_count[b], one per list); not
  // joined.
  void offsets_from_blocks(std::size_t n);
  void join();  // copies the lists into index (in parallel) from the blocks or from `within`; nothing if joined
  void held_joined() {  // the lists are (being) written into index
    joined = true;
    within = nullptr;
    tiled = false;
  }
  void view_inside(const NeighbourLists& lists) {  // offsets and start set
    joined = false;
    within = &lists;
    tiled = false;
  }
  void held_in_tiles() {  // offsets and start set
    joined = false;
    within = nullptr;
    tiled = true;
  }

  std::size_t bytes() const;  // memory held (capacities, builder scratch included)
};

// Any cell size works; cells of about radius/2 scan the fewest candidates (5 x 5 cells of h^2
// against 3 x 3 of 4 h^2 for a support radius 2h).
// Lists are made for the first `count` particles (the rest, e.g. ghosts, are only candidates).
template <int D>
void build_neighbour_lists(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, double radius, NeighbourLists& out,
                           std::size_t count = SIZE_MAX);

// Half lists for evaluating each pair once (pair_lists.hpp): j is in i's list when
// |x_i - x_j| < radius, j comes after i in cell order (slot[j] > slot[i], slot: each particle's
// place in grid.sorted) and i or j is below `writable`. Only the half of the stencil after i is
// scanned. Lists for all particles, in the order the pair loops visit them: list k is particle
// order[k]'s (a permutation of the particles; pair_lists.hpp).
// join = false leaves them in the builder's blocks (NeighbourLists::joined), where the pair loops
// read them (pair_lists.hpp).
template <int D>
void build_half_neighbour_lists(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, double radius,
                                const std::vector<std::uint32_t>& slot, std::size_t writable,
                                const std::vector<std::uint32_t>& order, NeighbourLists& out, bool join = true);

// Gather lists with a search radius per particle (variable smoothing lengths): j is in i's list
// when |x_i - x_j| < radius[i]. The cell size may be smaller than the radii; more cells are scanned.
// Lists are made for the first `count` particles (the rest are only candidates).
template <int D>
void build_neighbour_lists(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, const std::vector<double>& radius,
                           NeighbourLists& out, std::size_t count = SIZE_MAX);

// Gather lists whose radius each particle settles from its own candidates: particle i's
// candidates within first_radius[i] are passed to settle(i, candidates, dist2, searched_radius),
// dist2[k] = |x_i - x_candidates[k]|^2 (the search computed them anyway; passed on, they spare the
// solve a gather of positions by index), which returns the radius to keep (<= searched; entries
// beyond it are dropped, order kept) or a larger radius to search again. Used to solve adaptive
// smoothing lengths during the search itself (physics/smoothing_length.hpp). settle runs in
// parallel, once per particle and search.
using SettleRadius = std::function<double(std::size_t, std::span<const std::uint32_t>, std::span<const double>, double)>;

// Lists are made for the first `count` particles (the rest, e.g. ghosts, are only candidates).
// join = false leaves them in the builder's blocks (NeighbourLists::joined).
// visit: null, or the order of the lists (list k is particle visit[k]'s; a permutation of the first
// `count` particles), e.g. the pair loops' tile order (pair_lists.hpp).
template <int D>
void build_settled_neighbour_lists(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos,
                                   const std::vector<double>& first_radius, const SettleRadius& settle,
                                   NeighbourLists& out, std::size_t count = SIZE_MAX, bool join = true,
                                   const std::uint32_t* visit = nullptr);

// The same search with nothing listed: settle(i, candidates, dist2, radius) alone sees each particle's
// candidates (the smoothing-length solve of a run that keeps no lists, pair_scan.hpp), and at most
// one particle's candidates per thread are held at a time.
template <int D>
void settle_without_lists(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, const std::vector<double>& first_radius,
                          const SettleRadius& settle, std::size_t count = SIZE_MAX);

// Extends lists made for particles [0, first) with gather lists (|x_i - x_j| < radius[i]) of the
// particles [first, pos.size()), holding only the neighbours with an index below candidates_below
// (all by default; fewer when only those particles' pairs are wanted, e.g. the active ones of a
// block timestep, and then the rows of cells without any are not scanned). Joins `out` first.
template <int D>
void append_neighbour_lists(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, std::size_t first,
                            const std::vector<double>& radius, NeighbourLists& out,
                            std::size_t candidates_below = SIZE_MAX);

template <int D>
NeighbourLists build_neighbour_lists(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, double radius) {
  NeighbourLists nl;
  build_neighbour_lists(grid, pos, radius, nl);
  return nl;
}

}  // namespace sphdisk

