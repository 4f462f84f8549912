#pragma once
// Search radii, halo margins and the pair schedule's tile size of a rate evaluation
// (rate_evaluator.cpp, adaptive_search.cpp, partial_evaluation.cpp): choices of the evaluation,
// not of the physics, that several of its stages share.
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "parallel/loops.hpp"
#include "parallel/nth_values.hpp"

namespace sphdisk::evaluation {

// Candidates are searched to kSkin x 2 h_i, so h may grow by kSkin while it is solved for before
// the particle's search must be repeated.
constexpr double kSkin = 1.05;

// The cell size over the median h: kSkin in 2D, so that the median particle's search (radius
// 2 kSkin h) spans two cells each side; twice that in 3D, one cell each side: a 3D search visits
// (2 reach + 1)^2 rows of cells, and with reach 1 instead of 2 the rows' fixed cost saves more than
// the extra candidates cost (docs/performance.md, "Three dimensions: Phantom's test disc").
template <int D>
constexpr double kCellOverMedianH = D == 3 ? 2.0 * kSkin : kSkin;

// Halos (ghosts of other ranks, or the involved particles of a partial evaluation) reach this much
// beyond the first search radius, so that h may grow by it before the solve must be repeated.
constexpr double kHaloMargin = 1.25;

// Tiles of the pair schedule (pair_lists.hpp) span at least 16 x 16 cells in 2D (4^3 of 3D's twice
// larger cells), ~1,000 particles: tiles that run side by side lie apart, so what a tile reads of
// its neighbours is reused only inside the tile, and larger tiles reuse more of it (docs/performance.md,
// "Neighbour search and pair lists"). The tiles also span the supports of all but the widest 1%
// of particles, whose pairs reaching beyond the next tile are evaluated after the others. The tile
// size depends on the particles only, never on the thread count (it sets the order of the sums).
template <int D>
constexpr int kMinTileCells = D == 2 ? 16 : 4;
constexpr double kTileQuantile = 0.99;

// The k-th smallest (from 0) of v for k = fraction * size, for each of the fractions (< 1).
template <std::size_t N>
std::array<double, N> quantiles(const std::vector<double>& v, const std::array<double, N>& fractions) {
  std::array<std::size_t, N> ranks{};
  for (std::size_t f = 0; f < N; ++f) ranks[f] = static_cast<std::size_t>(fractions[f] * static_cast<double>(v.size()));
  return par::nth_values(v, ranks);
}

// One process, adaptive h: the cell size (from the median h: the denser particles scan few cells
// and the rest reach over more; any cell size gives the same lists) and the support the tiles span
// (all but the widest 1%), from every particle's h.
struct CellsAndTiles {
  double cell_size, widest_support;
};
template <int D>
CellsAndTiles cells_and_tiles(const std::vector<double>& h) {
  const auto [median, wide] = quantiles<2>(h, {0.5, kTileQuantile});
  return {kCellOverMedianH<D> * median, 2.0 * wide};
}

inline std::size_t total_of(const std::vector<std::uint32_t>& counts) {
  return par::sum<std::size_t>(counts.size(), [&](std::size_t i) { return static_cast<std::size_t>(counts[i]); });
}

}  // namespace sphdisk::evaluation
