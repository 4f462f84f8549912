// The 2D rows of cells a search visits (neighbours/candidate_ranges.hpp, row_ranges): the AVX-512
// path (where the CPU has it) must give the scalar path's slot ranges exactly, for points inside
// and outside the grid, on cell edges, with radii from a fraction of a cell to beyond the grid, with
// and without the half search's own slot; the neighbour lists built on either path equal a brute
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

}  // namespace

TEST(CandidateRows, VectorPathGivesTheScalarRanges) {
  if (cpu_vector_isa() < VectorIsa::avx512) GTEST_SKIP() << "this CPU has no AVX-512: only the scalar rows run";
  const auto p = test::random_particles<2>(4000, 21, true);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.2, 1.2);  // the particles lie in [0, 1]^2: some points outside
  std::size_t rows_with_slots = 0, own_rows = 0;
  for (const double cell : {0.013, 0.05, 0.31}) {
    const auto grid = build_cell_grid(p.pos, p.id, cell);
    for (int k = 0; k < 3000; ++k) {
      Vec<2> x{{u(rng), u(rng)}};
      if (k % 3 == 0) x[0] = grid.lo[0] + grid.cell_size * static_cast<double>(k % 17);  // on a cell edge
      if (k % 5 == 0) x[1] = grid.lo[1] + grid.cell_size * static_cast<double>(k % 13);
      double radius = grid.cell_size * (k % 7 == 0 ? 40.0 : 0.1 + 3.0 * u(rng) * u(rng));
      if (k % 4 == 1) {  // on a corner, radius 5 cells: the rows 3 cells away end their chords on edges
        x = Vec<2>{{grid.lo[0] + grid.cell_size * static_cast<double>(k % 23), grid.lo[1] + grid.cell_size * static_cast<double>(k % 19)}};
        radius = 5.0 * grid.cell_size;
      }
      const std::uint32_t own = static_cast<std::uint32_t>(k % grid.sorted.size());
      for (const std::uint32_t* after : {static_cast<const std::uint32_t*>(nullptr), &own}) {
        const Ranges scalar = ranges_on(VectorIsa::baseline, grid, x, radius, after);
        const Ranges vector = ranges_on(VectorIsa::avx512, grid, x, radius, after);
        ASSERT_EQ(vector, scalar) << "cell " << cell << " point " << k << (after ? " (half)" : "");
        for (std::size_t r = 0; r < scalar.s0.size(); ++r) rows_with_slots += scalar.s0[r] < scalar.s1[r];
        own_rows += after != nullptr && scalar.s0[0] == own + 1;
      }
    }
  }
  EXPECT_GT(rows_with_slots, 10000u);  // the rows hold candidates, not only empty ranges
  EXPECT_GT(own_rows, 1000u);          // the half search's own row starts after its slot
}
