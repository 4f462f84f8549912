#pragma once
// The candidate neighbours of a point as contiguous ranges of a cell grid's slots (cell_grid.hpp),
// shared by the neighbour-list builders (neighbour_lists.cpp) and the pair loops that search
// their partners anew instead of storing lists (pair_scan.hpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "core/vec.hpp"
#include "neighbours/cell_grid.hpp"

namespace sphdisk {

// Cells to scan on each side of a point's cell for neighbours within `radius` (a radius of exactly k
// cells needs k: the margin keeps round-off from adding a row).
template <int D>
int cells_within(const CellGrid<D>& g, double radius) {
  return static_cast<int>(std::ceil(radius / g.cell_size - 1e-12));
}

// Visits the candidate neighbours of x: the cells within `reach` cells of its cell in every
// dimension. With x-fastest cell order, the cells of a row are adjacent in `sorted`, so each row is
// one contiguous range. With `after` (x's own slot) only the candidates after it in cell order: the
// rest of x's own row of cells, then the rows above (and in 3D the layers above), so that each pair
// is seen from its first particle only (P98's symmetric sequential variant, Fig. 4).
template <int D, class F>
void for_each_candidate_range(const CellGrid<D>& g, const Vec<D>& x, int reach, F&& f,
                              const std::uint32_t* after = nullptr) {
  std::array<int, D> c;
  for (int k = 0; k < D; ++k) c[static_cast<std::size_t>(k)] = g.coord(x[k], k);
  const int x0 = std::max(c[0] - reach, 0), x1 = std::min(c[0] + reach, g.dims[0] - 1);
  const auto first = [&](int k) { return after ? c[static_cast<std::size_t>(k)] : std::max(c[static_cast<std::size_t>(k)] - reach, 0); };
  std::array<int, D> r = c;
  auto row = [&](std::array<int, D> cell) {
    const bool own_row = after && cell == c;
    cell[0] = x1;
    const std::uint32_t end = g.offsets[g.linear(cell) + 1];
    cell[0] = x0;
    f(own_row ? *after + 1 : g.offsets[g.linear(cell)], end);
  };
  if constexpr (D == 1) {
    row(r);
  } else if constexpr (D == 2) {
    for (int y = first(1); y <= std::min(c[1] + reach, g.dims[1] - 1); ++y) {
      r[1] = y;
      row(r);
    }
  } else {
    for (int z = first(2); z <= std::min(c[2] + reach, g.dims[2] - 1); ++z)
      for (int y = z == c[2] ? first(1) : std::max(c[1] - reach, 0); y <= std::min(c[1] + reach, g.dims[1] - 1); ++y) {
        r[1] = y;
        r[2] = z;
        row(r);
      }
  }
}

}  // namespace sphdisk
