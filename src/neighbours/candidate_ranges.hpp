#pragma once
// The candidate neighbours of a point as contiguous ranges of a cell grid's slots (cell_grid.hpp),
// shared by the neighbour-list builders (neighbour_lists.cpp) and the pair loops that search
// their partners anew instead of storing lists (pair_scan.hpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>

#include "core/vec.hpp"
#include "neighbours/cell_grid.hpp"

namespace sphdisk {

// Cells to scan on each side of a point's cell for neighbours within `radius` (a radius of exactly k
// cells needs k: the margin keeps round-off from adding a row).
template <int D>
int cells_within(const CellGrid<D>& g, double radius) {
  return static_cast<int>(std::ceil(radius / g.cell_size - 1e-12));
}

// What the rows of one point's search share (row_range, row_ranges).
template <int D>
struct RowSearch {
  Vec<D> x;
  double radius;
  std::array<int, D> c;  // x's cell
  int reach;             // cells_within(radius)
  int x0, x1;            // the cells within reach along x
  double margin;         // for the round-off of the cell coordinates
  double inv_cell;
  const std::uint32_t* after;  // x's own slot, or null: see for_each_candidate_range
};

template <int D>
RowSearch<D> row_search(const CellGrid<D>& g, const Vec<D>& x, double radius, const std::uint32_t* after) {
  RowSearch<D> q{x, radius, {}, cells_within(g, radius), 0, 0, 1e-9 * g.cell_size, 1.0 / g.cell_size, after};
  for (int k = 0; k < D; ++k) q.c[static_cast<std::size_t>(k)] = g.coord(x[k], k);
  q.x0 = std::max(q.c[0] - q.reach, 0);
  q.x1 = std::min(q.c[0] + q.reach, g.dims[0] - 1);
  return q;
}

// The slots [s0, s1) of the row of cells through `cell` (its x coordinate ignored) that the chord
// of q's circle (sphere) reaches at the row's nearest distance from x; s0 >= s1: nothing to scan.
// Each row's range is a chain of a square root and divisions (row_ranges forms up to eight at once
// where the CPU has AVX-512: candidate_rows.cpp).
template <int D>
std::pair<std::uint32_t, std::uint32_t> row_range(const CellGrid<D>& g, const RowSearch<D>& q, std::array<int, D> cell) {
  // The squared distance from x to the row's band of cells (its y, and in 3D z, extent).
  double d2 = 0;
  for (int k = 1; k < D; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    const double lo = g.lo[k] + (g.origin[kk] + cell[kk]) * g.cell_size;
    const double d = std::max({lo - q.x[k], q.x[k] - (lo + g.cell_size), 0.0});
    const double dm = std::max(d - q.margin, 0.0);
    d2 += dm * dm;
  }
  if (d2 >= q.radius * q.radius) return {0, 0};
  const double half_chord = std::sqrt(q.radius * q.radius - d2) + q.margin;
  bool own_row = q.after != nullptr;
  for (int k = 1; k < D; ++k) own_row = own_row && cell[static_cast<std::size_t>(k)] == q.c[static_cast<std::size_t>(k)];
  // The cells of the row that the chord reaches (the same coordinates as the particles': every
  // particle within the chord lies in one of them). The chord's end cells by a product with the
  // inverse cell size, not a division per row: that rounds differently from coord() by ~1e-16 of
  // the coordinate, far inside the margin, so no cell that holds a point within the radius is
  // missed (an extra cell holds only points beyond it).
  cell[0] = std::min(q.x1, g.coord_in_cells((q.x[0] + half_chord - g.lo[0]) * q.inv_cell, 0));
  const std::uint32_t s1 = g.offsets[g.linear(cell) + 1];
  cell[0] = std::max(q.x0, g.coord_in_cells((q.x[0] - half_chord - g.lo[0]) * q.inv_cell, 0));
  const std::uint32_t s0 = own_row ? *q.after + 1 : g.offsets[g.linear(cell)];
  return {s0, s1};
}

// The ranges of the 2D rows y0..y1 (at most kMaxRows), or of the n 3D rows (ys[k], zs[k]) of any
// layers (n at most kMaxRows; ys and zs with kMaxRows readable entries), row_range's for each
// (candidate_rows.cpp).
constexpr int kMaxRows = 16;
void row_ranges(const CellGrid<2>& g, const RowSearch<2>& q, int y0, int y1, std::uint32_t* s0, std::uint32_t* s1);
void row_ranges(const CellGrid<3>& g, const RowSearch<3>& q, const int* ys, const int* zs, int n, std::uint32_t* s0,
                std::uint32_t* s1);

// Visits the candidate neighbours of x within `radius`: in each row of cells within reach (the
// cells within cells_within(radius) of x's cell in every dimension), the cells that the chord of
// the circle (sphere) of that radius reaches at the row's nearest distance from x (row_range); rows
// beyond the radius are skipped. With x-fastest cell order the cells of a row are adjacent in
// `sorted`, so each row is one contiguous range. Every point within the radius is visited (the
// chord has a margin for the round-off of the cell coordinates); points beyond it may be. On the
// ring this cuts the candidates by about a third against whole rows (docs/performance.md,
// "Neighbour search and pair lists"). With `after` (x's own slot) only the candidates after it in
// cell order: the rest of x's own row of cells, then the rows above (and in 3D the layers above), so
// that each pair is seen from its first particle only (P98's symmetric sequential variant, Fig. 4).
template <int D, class F>
void for_each_candidate_range(const CellGrid<D>& g, const Vec<D>& x, double radius, F&& f,
                              const std::uint32_t* after = nullptr) {
  const RowSearch<D> q = row_search(g, x, radius, after);
  const int reach = q.reach;
  const auto first = [&](int k) {
    const int ck = q.c[static_cast<std::size_t>(k)];
    return after ? ck : std::max(ck - reach, 0);
  };
  // The rows' ranges first, kMaxRows at a time, then the scans. The chains of different rows overlap
  // only when no scan lies between them (docs/performance.md, "Neighbour search and pair lists").
  std::array<std::uint32_t, kMaxRows> s0, s1;
  const auto scan = [&](int n) {
    for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k)
      if (s0[k] < s1[k]) f(s0[k], s1[k]);
  };
  if constexpr (D == 1) {
    const auto [a, b] = row_range<D>(g, q, q.c);
    if (a < b) f(a, b);
  } else if constexpr (D == 2) {
    const int y1 = std::min(q.c[1] + reach, g.dims[1] - 1);
    for (int ya = first(1); ya <= y1; ya += kMaxRows) {
      const int yb = std::min(y1, ya + kMaxRows - 1);
      row_ranges(g, q, ya, yb, s0.data(), s1.data());
      scan(yb - ya + 1);
    }
  } else {
    // The rows of all layers in turn (z outer, y inner), gathered across layers so that a search of
    // reach 1 forms its nine rows' ranges in two vector rounds rather than three.
    std::array<int, kMaxRows> ys{}, zs{};
    int n = 0;
    for (int z = first(2); z <= std::min(q.c[2] + reach, g.dims[2] - 1); ++z) {
      const int y1 = std::min(q.c[1] + reach, g.dims[1] - 1);
      for (int y = z == q.c[2] ? first(1) : std::max(q.c[1] - reach, 0); y <= y1; ++y) {
        ys[static_cast<std::size_t>(n)] = y;
        zs[static_cast<std::size_t>(n)] = z;
        if (++n == kMaxRows) {
          row_ranges(g, q, ys.data(), zs.data(), n, s0.data(), s1.data());
          scan(n);
          n = 0;
        }
      }
    }
    if (n > 0) {
      row_ranges(g, q, ys.data(), zs.data(), n, s0.data(), s1.data());
      scan(n);
    }
  }
}

}  // namespace sphdisk
