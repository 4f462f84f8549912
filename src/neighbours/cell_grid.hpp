#pragma once
// Cell linked list (P98 sec. 4.1, after Allen & Tildesley) in its cache-friendly form: a
// permutation of particle indices sorted by cell plus an offsets array of size ncells + 1 (as in
// AMReX). Built in O(N) by a counting sort. Inside a cell, particles are ordered by x, then by
// particle ID, so neighbour order, and hence every floating-point sum, depends only on positions
// and IDs — not on memory order, thread count or rank count. Ordered by x (not by ID alone), the
// runs reordered in this order keep neighbours closer in memory, and the pair loops run faster
// than with ID order inside cells (docs/performance.md, "Neighbour search and pair lists").
//
// The cells are those of a Lattice (corner, cell size), which every rank of a distributed run shares;
// a rank's grid covers only the lattice cells around its own particles (origin = the lattice index
// of its cell (0, ..., 0)). Cell coordinates are always computed from the lattice corner, so a
// particle falls into the same cell on every rank and neighbours come in the same order.
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "core/vec.hpp"

namespace sphdisk {

template <int D>
struct Lattice {
  Vec<D> lo;             // corner of lattice cell (0, ..., 0)
  double cell_size = 0;
  std::array<int, D> dims{};  // cells per dimension covering all particles (of all ranks)
};

// The lattice over the box [lo, hi] holding n particles in total, with cells no smaller than
// min_cell_size. The cell size grows if needed to keep the number of cells <= max(4 n, 1024): a
// stray far-away particle cannot blow up memory.
template <int D>
Lattice<D> make_lattice(const Vec<D>& lo, const Vec<D>& hi, std::size_t n, double min_cell_size);

template <int D>
struct CellGrid {
  Vec<D> lo;                    // corner of the lattice (not of this grid)
  double cell_size = 0;         // >= interaction radius
  std::array<int, D> origin{};  // lattice index of this grid's cell (0, ..., 0)
  std::array<int, D> dims{};    // cells per dimension
  std::vector<std::uint32_t> sorted;   // particle indices, cell by cell
  std::vector<std::uint32_t> offsets;  // cell c holds sorted[offsets[c] .. offsets[c+1])
  std::vector<Vec<D>> sorted_pos;      // pos[sorted[s]]: candidates are scanned contiguously
  std::vector<std::uint32_t> key;      // scratch: cell of each particle

  std::size_t num_cells() const { return offsets.empty() ? 0 : offsets.size() - 1; }
  std::size_t bytes() const {  // memory held (capacities)
    return (sorted.capacity() + offsets.capacity() + key.capacity()) * sizeof(std::uint32_t) +
           sorted_pos.capacity() * sizeof(Vec<D>);
  }
  // The cell coordinate of x along axis k, clamped to [0, dims[k]). Inline, and floor only for a
  // negative quotient: for t >= 0, floor(t) is the truncation, and x86-64's baseline has no
  // rounding instruction, so std::floor would be a call in every row of every search. The same
  // cells as floor((x - lo) / cell_size) - origin.
  int coord(double x, int k) const { return coord_in_cells((x - lo[k]) / cell_size, k); }
  // The same for t = (x - lo) / cell_size given (for callers that may round t differently, e.g.
  // multiply by the inverse cell size, and allow for it).
  int coord_in_cells(double t, int k) const {
    const auto kk = static_cast<std::size_t>(k);
    const double first = origin[kk];
    if (!(t >= first)) return 0;  // also catches NaN
    if (t >= first + dims[kk]) return dims[kk] - 1;
    const double whole = t >= 0 ? static_cast<double>(static_cast<std::int64_t>(t)) : std::floor(t);
    return static_cast<int>(whole - first);
  }
  // x fastest: cells along x are adjacent, so a row of cells is one contiguous range of slots.
  std::size_t linear(const std::array<int, D>& c) const {
    std::size_t idx = 0;
    for (int k = D - 1; k >= 0; --k)
      idx = idx * static_cast<std::size_t>(dims[static_cast<std::size_t>(k)]) + static_cast<std::size_t>(c[static_cast<std::size_t>(k)]);
    return idx;
  }
  std::size_t cell_of(const Vec<D>& x) const;
};

// Builds the grid over the bounding box of pos on make_lattice's lattice (one process holding all
// particles). Fills `g` in place, reusing its memory.
template <int D>
void build_cell_grid(const std::vector<Vec<D>>& pos, const std::vector<std::uint64_t>& id, double min_cell_size,
                     CellGrid<D>& g);

// Builds the grid of the lattice cells that hold pos (this rank's particles and ghosts).
template <int D>
void build_cell_grid(const Lattice<D>& lattice, const std::vector<Vec<D>>& pos, const std::vector<std::uint64_t>& id,
                     CellGrid<D>& g);

template <int D>
CellGrid<D> build_cell_grid(const std::vector<Vec<D>>& pos, const std::vector<std::uint64_t>& id,
                            double min_cell_size) {
  CellGrid<D> g;
  build_cell_grid(pos, id, min_cell_size, g);
  return g;
}

// Bounding box shared by the grid builder and the tests.
template <int D>
void bounding_box(const std::vector<Vec<D>>& pos, Vec<D>& lo, Vec<D>& hi);

// The grid of particles that did not move but of which the first moved.size() were renumbered:
// particle k is now the one that was particle moved[k] (a permutation of 0 .. moved.size() - 1).
// Cells and their order stay as they are.
template <int D>
void renumber_particles(CellGrid<D>& g, std::span<const std::uint32_t> moved);

}  // namespace sphdisk
