#pragma once
// Two-level domain decomposition (P98 sec. 4.4): the fine lattice of the neighbour search is grouped
// into top cells of block^D lattice cells; top cells are ordered along a Morton (Z-order) curve and
// cut into contiguous runs of equal particle count, one run per rank. A particle belongs to the rank
// of its top cell. Everything here is a pure function of the global per-top-cell counts (exact
// integers), so every rank computes the same owners without further communication.
#include <array>
#include <cstdint>
#include <vector>

#include "core/vec.hpp"
#include "neighbours/cell_grid.hpp"

namespace sphdisk {

template <int D>
struct Decomposition {
  Lattice<D> lattice;              // the fine lattice every rank's cell grid is built on
  int block = 1;                   // lattice cells per top-cell edge
  std::array<int, D> top_dims{};   // top cells per dimension
  std::vector<int> owner;          // rank of each top cell (x-fastest linear index)

  std::size_t top_cells() const { return owner.size(); }
  std::array<int, D> top_coord(const Vec<D>& x) const;  // clamped to the top grid
  std::size_t top_index(const std::array<int, D>& t) const;
  std::size_t top_cell_of(const Vec<D>& x) const { return top_index(top_coord(x)); }
  int owner_of(const Vec<D>& x) const { return owner[top_cell_of(x)]; }
  // Squared distance from x to the box of top cell t (0 inside).
  double distance2_to(const Vec<D>& x, const std::array<int, D>& t) const;
};

// The top grid over `lattice` with about `target_cells` top cells (at least one lattice cell each).
template <int D>
Decomposition<D> make_top_grid(const Lattice<D>& lattice, std::size_t target_cells);

// Morton key of a top cell (bits of the coordinates interleaved).
template <int D>
std::uint64_t morton_key(const std::array<int, D>& t);

// Fills d.owner: top cells in Morton order, cut into `ranks` runs of about equal total weight
// (weights[c]: particles, or measured cost, of top cell c). Deterministic.
template <int D>
void assign_owners(Decomposition<D>& d, const std::vector<std::uint64_t>& weights, int ranks);

}  // namespace sphdisk
