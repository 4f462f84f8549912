#pragma once
// Cell linked list (P98 sec. 4.1, after Allen & Tildesley) in its cache-friendly form: a
// permutation of particle indices sorted by cell plus an offsets array of size ncells + 1 (as in
// AMReX). Built in O(N) by a counting sort. Inside a cell, particles are ordered by particle ID, so
// neighbour order, and hence every floating-point sum, depends only on positions and IDs — not on
// memory order, thread count or (later) rank count.
#include <array>
#include <cstdint>
#include <vector>

#include "core/vec.hpp"

namespace sphdisk {

template <int D>
struct CellGrid {
  Vec<D> lo;                    // lower corner of cell (0, ..., 0)
  double cell_size = 0;         // >= interaction radius
  std::array<int, D> dims{};    // cells per dimension
  std::vector<std::uint32_t> sorted;   // particle indices, cell by cell
  std::vector<std::uint32_t> offsets;  // cell c holds sorted[offsets[c] .. offsets[c+1])
  std::vector<Vec<D>> sorted_pos;      // pos[sorted[s]]: candidates are scanned contiguously
  std::vector<std::uint32_t> key;      // scratch: cell of each particle

  std::size_t num_cells() const { return offsets.empty() ? 0 : offsets.size() - 1; }
  int coord(double x, int k) const;                  // clamped to [0, dims[k])
  std::size_t linear(const std::array<int, D>& c) const;
  std::size_t cell_of(const Vec<D>& x) const;
};

// Builds the grid over the bounding box of pos with cells no smaller than min_cell_size. The cell
// size grows if needed to keep the number of cells <= max(4 N, 1024): a stray far-away particle
// cannot blow up memory.
// Fills `g` in place, reusing its memory.
template <int D>
void build_cell_grid(const std::vector<Vec<D>>& pos, const std::vector<std::uint64_t>& id, double min_cell_size,
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

}  // namespace sphdisk
