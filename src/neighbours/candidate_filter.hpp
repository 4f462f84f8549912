#pragma once
// Which cell-grid candidates count when only the particles below an index do (ghosts and inactive
// particles pair only with writable ones): a prefix count over the grid's slots that skips rows of
// cells without such candidates, and two tests that dismiss a particle with none within reach
// before its rows are formed. Used by the neighbour-list builders (neighbour_lists.cpp) and by the
// pair loops that search their pairs anew (pair_scan.hpp).
#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/vec.hpp"
#include "neighbours/candidate_ranges.hpp"
#include "neighbours/cell_grid.hpp"
#include "parallel/loops.hpp"

namespace sphdisk {

// Only candidates with an index below `below` are listed; rows of cells that hold none are skipped
// by a prefix count over the grid's slots (empty when every candidate counts).
struct CandidateFilter {
  std::uint32_t below = UINT32_MAX;
  std::vector<std::uint32_t> slot_prefix;  // slot_prefix[s]: slots before s that hold a candidate below `below`
  // 2D: a summed-area table of the candidates per cell ((dims[0] + 1) x (dims[1] + 1), x fastest),
  // so that a particle with none in the square of cells within its reach is skipped before its
  // rows are formed (with block timesteps most inactive particles lie far from every active one).
  std::vector<std::uint32_t> cell_sum;
  // The candidates' bounding box (any D): a particle farther from it than its radius has none
  // within reach. With block timesteps the few active particles of the shortest steps crowd the
  // centre, and this test (a few comparisons) dismisses nearly every inactive particle before the
  // table's cell coordinates are formed.
  bool boxed = false;
  Vec<3> box_lo{}, box_hi{};

  template <int D>
  void bound(const std::vector<Vec<D>>& pos) {
    boxed = true;
    for (int k = 0; k < D; ++k) {
      box_lo[k] = std::numeric_limits<double>::infinity();
      box_hi[k] = -std::numeric_limits<double>::infinity();
    }
    for (std::size_t i = 0; i < std::min<std::size_t>(below, pos.size()); ++i)
      for (int k = 0; k < D; ++k) {
        box_lo[k] = std::min(box_lo[k], pos[i][k]);
        box_hi[k] = std::max(box_hi[k], pos[i][k]);
      }
  }

  template <int D>
  void count_per_cell(const CellGrid<D>& grid) {
    if constexpr (D == 2) {
      const std::size_t nx = static_cast<std::size_t>(grid.dims[0]), ny = static_cast<std::size_t>(grid.dims[1]), w = nx + 1;
      cell_sum.resize(w * (ny + 1));
      // Row by row the sums along x, then column by column along y (each pass in parallel; integer
      // sums, so the table of the serial recurrence).
      std::fill_n(cell_sum.begin(), w, 0u);
      par::for_each(ny, [&](std::size_t y) {
        std::uint32_t* row = cell_sum.data() + (y + 1) * w;
        row[0] = 0;
        for (std::size_t x = 0; x < nx; ++x) {
          const std::size_t c = y * nx + x;  // CellGrid::linear
          row[x + 1] = row[x] + (slot_prefix[grid.offsets[c + 1]] - slot_prefix[grid.offsets[c]]);
        }
      }, {}, 16);
      par::for_each(w, [&](std::size_t x) {
        for (std::size_t y = 1; y <= ny; ++y) cell_sum[y * w + x] += cell_sum[(y - 1) * w + x];
      }, {}, 64);
    }
  }

  // Whether any candidate lies in the cells within `radius` of x (2D with a table; else true).
  template <int D>
  bool any_within(const CellGrid<D>& grid, const Vec<D>& x, double radius) const {
    return any_within_box(grid, x, x, radius);
  }

  // The same for every point of the box [lo, hi] at once: false only when no candidate lies within
  // `radius` of any of them (a whole tile of the pair schedule dismissed, pair_scan.hpp).
  template <int D>
  bool any_within_box(const CellGrid<D>& grid, const Vec<D>& lo, const Vec<D>& hi, double radius) const {
    if (boxed) {
      double d2 = 0;  // squared distance between the boxes: at most that between any two of their
                      // points, each difference and sum rounded no larger; the margin covers a fused norm2
      for (int k = 0; k < D; ++k) {
        const double gap = std::max({box_lo[k] - hi[k], lo[k] - box_hi[k], 0.0});
        d2 += gap * gap;
      }
      if (d2 > radius * radius * (1.0 + 1e-9)) return false;
    }
    if constexpr (D == 2) {
      if (cell_sum.empty()) return true;
      const int reach = cells_within(grid, radius);
      std::size_t first[2], last[2];  // the cells within reach of the box's cells, [first, last) per axis
      for (int k = 0; k < 2; ++k) {
        first[k] = static_cast<std::size_t>(std::max(grid.coord(lo[k], k) - reach, 0));
        last[k] = static_cast<std::size_t>(std::min(grid.coord(hi[k], k) + reach, grid.dims[static_cast<std::size_t>(k)] - 1)) + 1;
      }
      const std::size_t x0 = first[0], x1 = last[0], y0 = first[1], y1 = last[1], w = static_cast<std::size_t>(grid.dims[0]) + 1;
      return cell_sum[y1 * w + x1] - cell_sum[y0 * w + x1] - cell_sum[y1 * w + x0] + cell_sum[y0 * w + x0] != 0;
    } else {
      return true;
    }
  }

  // Only the particles below `below` as candidates (nothing filtered when below >= pos.size()).
  template <int D>
  void build(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, std::size_t below_) {
    slot_prefix.clear();
    cell_sum.clear();
    boxed = false;
    below = UINT32_MAX;
    if (below_ >= pos.size()) return;
    below = static_cast<std::uint32_t>(below_);
    par::prefix_offsets(grid.sorted.size(), [&](std::size_t s) { return std::size_t{grid.sorted[s] < below_}; },
                        slot_prefix);
    count_per_cell(grid);
    bound(pos);
  }

  std::size_t bytes() const { return (slot_prefix.capacity() + cell_sum.capacity()) * sizeof(std::uint32_t); }
};

}  // namespace sphdisk
