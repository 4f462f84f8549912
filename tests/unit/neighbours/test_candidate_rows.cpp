// The rows of cells a search visits, in 2D and in 3D, where a batch of rows spans layers (neighbours/
// candidate_ranges.hpp, row_ranges): the AVX-512 path (where the CPU has it) must give the scalar
// path's slot ranges exactly, for points inside and outside the grid, on cell edges, with radii from
// a fraction of a cell to beyond the grid, with and without the half search's own slot; the neighbour lists built on either path equal a brute
// force search (test_neighbours.cpp runs on the widest path).
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "core/vector_isa.hpp"
#include "neighbours/candidate_ranges.hpp"
#include "test_helpers.hpp"

using namespace sphdisk;

namespace {

struct Ranges {
  std::vector<std::uint32_t> s0, s1;
  bool operator==(const Ranges&) const = default;
};

Ranges ranges_on(VectorIsa isa, const CellGrid<2>& g, const Vec<2>& x, double radius, const std::uint32_t* after) {
  return test::on_path(isa, [&] {
    const RowSearch<2> q = row_search(g, x, radius, after);
    const int y0 = after ? q.c[1] : std::max(q.c[1] - q.reach, 0);
    const int y1 = std::min({q.c[1] + q.reach, g.dims[1] - 1, y0 + kMaxRows - 1});
    Ranges r{std::vector<std::uint32_t>(kMaxRows, 7), std::vector<std::uint32_t>(kMaxRows, 7)};
    row_ranges(g, q, y0, y1, r.s0.data(), r.s1.data());
    return r;
  });
}

// Up to kMaxRows of a 3D search's rows in for_each_candidate_range's order (layers outer, rows
// inner), from its `skip`-th row on, so that a batch may begin in any layer and span several.
Ranges ranges_on(VectorIsa isa, const CellGrid<3>& g, const Vec<3>& x, double radius, const std::uint32_t* after, int skip) {
  return test::on_path(isa, [&] {
    const RowSearch<3> q = row_search(g, x, radius, after);
    std::array<int, kMaxRows> ys{}, zs{};
    int n = 0;
    for (int z = after ? q.c[2] : std::max(q.c[2] - q.reach, 0); z <= std::min(q.c[2] + q.reach, g.dims[2] - 1); ++z)
      for (int y = after && z == q.c[2] ? q.c[1] : std::max(q.c[1] - q.reach, 0); y <= std::min(q.c[1] + q.reach, g.dims[1] - 1); ++y)
        if (skip-- <= 0 && n < kMaxRows) {
          ys[static_cast<std::size_t>(n)] = y;
          zs[static_cast<std::size_t>(n)] = z;
          ++n;
        }
    Ranges r{std::vector<std::uint32_t>(kMaxRows, 7), std::vector<std::uint32_t>(kMaxRows, 7)};
    row_ranges(g, q, ys.data(), zs.data(), n, r.s0.data(), r.s1.data());
    return r;
  });
}

// Calls f(grid, x, radius, k) for `searches` search points per cell size over random particles in
// [0, 1]^D: points inside and outside the grid, some on cell edges, radii from a tenth of a cell to
// three cells, and every ninth 40 cells (beyond the grid).
template <int D, class F>
void for_each_search(std::size_t particles, std::uint64_t seed, std::initializer_list<double> cells, int searches, F f) {
  const auto p = test::random_particles<D>(particles, seed, true);
  std::mt19937_64 rng(seed + 100);
  std::uniform_real_distribution<double> u(-0.2, 1.2);
  constexpr int every[3] = {3, 5, 7}, at[3] = {17, 13, 11};
  for (const double cell : cells) {
    const auto grid = build_cell_grid(p.pos, p.id, cell);
    for (int k = 0; k < searches; ++k) {
      Vec<D> x;
      for (int d = 0; d < D; ++d) x[d] = u(rng);
      for (int d = 0; d < D; ++d)
        if (k % every[d] == 0) x[d] = grid.lo[d] + grid.cell_size * static_cast<double>(k % at[d]);  // on a cell edge
      const double radius = grid.cell_size * (k % 9 == 0 ? 40.0 : 0.1 + 3.0 * u(rng) * u(rng));
      f(grid, x, radius, k);
    }
  }
}

}  // namespace

TEST(CandidateRows, VectorPathGivesTheScalarRangesIn3D) {
  if (cpu_vector_isa() < VectorIsa::avx512) GTEST_SKIP() << "this CPU has no AVX-512: only the scalar rows run";
  std::size_t rows_with_slots = 0, own_rows = 0;
  for_each_search<3>(6000, 23, {0.04, 0.11, 0.4}, 1500, [&](const CellGrid<3>& grid, const Vec<3>& x, double radius, int k) {
    const std::uint32_t own = static_cast<std::uint32_t>(k % grid.sorted.size());
    for (const std::uint32_t* after : {static_cast<const std::uint32_t*>(nullptr), &own})
      for (const int skip : {0, 2, 5, 9, 20}) {
        const Ranges scalar = ranges_on(VectorIsa::baseline, grid, x, radius, after, skip);
        const Ranges vector = ranges_on(VectorIsa::avx512, grid, x, radius, after, skip);
        ASSERT_EQ(vector, scalar) << "cell " << grid.cell_size << " point " << k << " from row " << skip << (after ? " (half)" : "");
        for (std::size_t r = 0; r < scalar.s0.size(); ++r) rows_with_slots += scalar.s0[r] < scalar.s1[r];
        own_rows += after != nullptr && skip == 0 && scalar.s0[0] == own + 1;
      }
  });
  EXPECT_GT(rows_with_slots, 10000u);  // the rows hold candidates, not only empty ranges
  EXPECT_GT(own_rows, 300u);           // the half search's own row starts after its slot
}

TEST(CandidateRows, VectorPathGivesTheScalarRanges) {
  if (cpu_vector_isa() < VectorIsa::avx512) GTEST_SKIP() << "this CPU has no AVX-512: only the scalar rows run";
  std::size_t rows_with_slots = 0, own_rows = 0;
  for_each_search<2>(4000, 21, {0.013, 0.05, 0.31}, 3000, [&](const CellGrid<2>& grid, Vec<2> x, double radius, int k) {
    if (k % 4 == 1) {  // on a corner, radius 5 cells: the rows 3 cells away end their chords on edges
      x = Vec<2>{{grid.lo[0] + grid.cell_size * static_cast<double>(k % 23), grid.lo[1] + grid.cell_size * static_cast<double>(k % 19)}};
      radius = 5.0 * grid.cell_size;
    }
    const std::uint32_t own = static_cast<std::uint32_t>(k % grid.sorted.size());
    for (const std::uint32_t* after : {static_cast<const std::uint32_t*>(nullptr), &own}) {
      const Ranges scalar = ranges_on(VectorIsa::baseline, grid, x, radius, after);
      const Ranges vector = ranges_on(VectorIsa::avx512, grid, x, radius, after);
      ASSERT_EQ(vector, scalar) << "cell " << grid.cell_size << " point " << k << (after ? " (half)" : "");
      for (std::size_t r = 0; r < scalar.s0.size(); ++r) rows_with_slots += scalar.s0[r] < scalar.s1[r];
      own_rows += after != nullptr && scalar.s0[0] == own + 1;
    }
  });
  EXPECT_GT(rows_with_slots, 10000u);  // the rows hold candidates, not only empty ranges
  EXPECT_GT(own_rows, 1000u);          // the half search's own row starts after its slot
}
