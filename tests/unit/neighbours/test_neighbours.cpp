// Neighbour lists from the cell grid must equal a brute-force O(N^2) search, in a fixed order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "neighbours/cell_grid.hpp"
#include "neighbours/neighbour_lists.hpp"
#include "parallel/loops.hpp"
#include "test_helpers.hpp"

using namespace sphdisk;

// cell_size: of the grid (default: the radius, one cell of reach); smaller cells make each search
// clip its rows of cells to the chord of its circle (candidate_ranges.hpp).
template <int D>
void check_against_brute_force(const Particles<D>& p, double radius, double cell_size = 0) {
  const auto grid = build_cell_grid(p.pos, p.id, cell_size > 0 ? cell_size : radius);
  const auto nl = build_neighbour_lists(grid, p.pos, radius);
  ASSERT_EQ(nl.size(), p.size());
  std::size_t total = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    std::vector<std::uint32_t> brute;
    for (std::size_t j = 0; j < p.size(); ++j)
      if (j != i && norm2(p.pos[j] - p.pos[i]) < radius * radius) brute.push_back(static_cast<std::uint32_t>(j));
    std::vector<std::uint32_t> got(nl.begin(i), nl.end(i));
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, brute) << "particle " << i;
    total += brute.size();
  }
  EXPECT_GT(total, p.size());  // the sets are dense enough to have neighbours
}

TEST(Neighbours, EqualBruteForceRandom2D) { check_against_brute_force(test::random_particles<2>(2000, 1, false), 0.05); }
TEST(Neighbours, EqualBruteForceClustered2D) { check_against_brute_force(test::random_particles<2>(2000, 2, true), 0.02); }
TEST(Neighbours, EqualBruteForceRandom3D) { check_against_brute_force(test::random_particles<3>(2000, 3, false), 0.12); }
TEST(Neighbours, EqualBruteForceClustered3D) { check_against_brute_force(test::random_particles<3>(2000, 4, true), 0.05); }

// A grid renumbered after a prefix of the particles was permuted (renumber_particles) is the grid
// built anew from the permuted particles: cells, their order and their contents.
template <int D>
void check_renumbered_grid(Particles<D> p, double cell_size) {
  CellGrid<D> grid;
  build_cell_grid(p.pos, p.id, cell_size, grid);
  const std::size_t prefix = 2 * p.size() / 3;
  std::vector<std::uint32_t> moved(prefix);
  for (std::size_t k = 0; k < prefix; ++k) moved[k] = static_cast<std::uint32_t>((k * 7919) % prefix);  // 7919 prime, coprime to prefix
  par::permute_prefix(p.pos, moved);
  par::permute_prefix(p.id, moved);
  renumber_particles(grid, std::span<const std::uint32_t>(moved));
  CellGrid<D> rebuilt;
  build_cell_grid(p.pos, p.id, cell_size, rebuilt);
  EXPECT_EQ(grid.sorted, rebuilt.sorted);
  EXPECT_EQ(grid.offsets, rebuilt.offsets);
  EXPECT_EQ(grid.sorted_pos, rebuilt.sorted_pos);
  bool any_moved = false;
  for (std::size_t k = 0; k < prefix; ++k) any_moved = any_moved || moved[k] != k;
  EXPECT_TRUE(any_moved);
}

TEST(CellGrid, RenumberedAsBuiltAnew) {
  check_renumbered_grid(test::random_particles<2>(3000, 5, true), 0.03);
  check_renumbered_grid(test::random_particles<3>(3000, 6, true), 0.08);
}

// Cells of a third and a fifth of the radius: rows of up to 11 cells, clipped to the chord at each
// row's nearest distance (a chord 1% short fails here). On a lattice with the cell size as spacing,
// particles sit on cell edges and at the chords' ends.
TEST(Neighbours, ChordClippedRowsLoseNothing) {
  check_against_brute_force(test::random_particles<2>(2000, 5, true), 0.05, 0.05 / 3.0);
  check_against_brute_force(test::random_particles<3>(2000, 6, true), 0.1, 0.1 / 3.0);
  const double dx = 0.025;
  const auto lattice = test::square_lattice(40, dx);
  check_against_brute_force(lattice, 2.5 * dx, dx);
  check_against_brute_force(lattice, 5.0 * dx * (1 + 1e-15), dx);
  check_against_brute_force(lattice, 5.0 * dx, 0.5 * dx);
}

TEST(Neighbours, FarOutlierDoesNotBlowUpTheGrid) {
  auto p = test::random_particles<2>(500, 5, false);
  p.pos[17] = Vec<2>{{1e9, -1e9}};
  const auto grid = build_cell_grid(p.pos, p.id, 0.05);
  EXPECT_LE(grid.num_cells(), 4 * p.size() + 1024);
  check_against_brute_force(p, 0.05);
}

// Order inside each list is by cell, then by x and particle ID: independent of memory order.
TEST(Neighbours, OrderDoesNotDependOnMemoryOrder) {
  auto p = test::random_particles<2>(3000, 6, true);
  const double radius = 0.03;
  const auto nl = build_neighbour_lists(build_cell_grid(p.pos, p.id, radius), p.pos, radius);
  std::vector<std::uint32_t> reversed(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) reversed[i] = static_cast<std::uint32_t>(p.size() - 1 - i);
  auto q = p;
  q.gather(reversed);
  const auto nq = build_neighbour_lists(build_cell_grid(q.pos, q.id, radius), q.pos, radius);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const std::size_t iq = p.size() - 1 - i;
    ASSERT_EQ(nl.count(i), nq.count(iq));
    for (std::size_t k = 0; k < nl.count(i); ++k) ASSERT_EQ(p.id[nl.begin(i)[k]], q.id[nq.begin(iq)[k]]);
  }
}

TEST(Neighbours, SameListsForAnyThreadCount) {
  const auto p = test::random_particles<2>(20000, 7, true);
  par::set_threads(1);
  const auto a = build_neighbour_lists(build_cell_grid(p.pos, p.id, 0.01), p.pos, 0.01);
  par::set_threads(3);
  const auto b = build_neighbour_lists(build_cell_grid(p.pos, p.id, 0.01), p.pos, 0.01);
  par::set_threads(0);
  EXPECT_EQ(a.offsets, b.offsets);
  EXPECT_EQ(a.index, b.index);
}

// A grid of many particles: every particle in its cell once, each cell's particles by x, then ID,
// for 1 and 3 threads.
TEST(CellGrid, EveryParticleInItsCellInOrder) {
  const auto p = test::random_particles<2>(150000, 8, true);
  for (const int threads : {1, 3}) {
    par::set_threads(threads);
    const auto g = build_cell_grid(p.pos, p.id, 0.004);
    par::set_threads(0);
    ASSERT_EQ(g.sorted.size(), p.size());
    ASSERT_EQ(g.offsets.size(), g.num_cells() + 1);
    std::vector<int> seen(p.size(), 0);
    for (std::size_t c = 0; c < g.num_cells(); ++c)
      for (std::uint32_t s = g.offsets[c]; s < g.offsets[c + 1]; ++s) {
        const std::uint32_t i = g.sorted[s];
        ++seen[i];
        ASSERT_EQ(g.cell_of(p.pos[i]), c) << "slot " << s;
        ASSERT_EQ(g.sorted_pos[s], p.pos[i]);
        if (s > g.offsets[c]) {
          const std::uint32_t before = g.sorted[s - 1];
          ASSERT_TRUE(p.pos[before][0] < p.pos[i][0] || (p.pos[before][0] == p.pos[i][0] && p.id[before] < p.id[i]));
        }
      }
    EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<std::ptrdiff_t>(p.size()));
  }
}

// A lattice with no lower bound on the cell size (a zero smoothing length) is sized by the cap on
// cells (at most max(4 n, 1024)), instead of never finishing.
TEST(Lattice, ZeroMinimumCellSizeIsCappedByTheCellCount) {
  const Vec<2> lo{{-1.0, -2.0}}, hi{{3.0, 1.0}};
  for (const double min_size : {0.0, -1.0, std::nan("")}) {
    const Lattice<2> L = make_lattice(lo, hi, 1000, min_size);
    ASSERT_GT(L.cell_size, 0.0);
    EXPECT_LE(static_cast<double>(L.dims[0]) * L.dims[1], 4000.0);
    EXPECT_GE(static_cast<double>(L.dims[0]) * L.dims[1], 4000.0 / 1.25 / 1.25 / 2);  // not needlessly coarse
  }
}

// Particles at a NaN or infinite position (a blown-up step) get an error, not a lattice that is
// grown for ever: a resumed block-timestep run whose density and stress had not been kept hung here.
TEST(Lattice, NonFiniteExtentIsAnErrorNotAHang) {
  const Vec<2> lo{{-1.0, -2.0}};
  for (const double bad : {std::nan(""), std::numeric_limits<double>::infinity()}) {
    const Vec<2> hi{{3.0, bad}};
    EXPECT_THROW(make_lattice(lo, hi, 1000, 0.1), NumericalError);
    EXPECT_THROW(make_lattice(lo, hi, 1000, 0.0), NumericalError);
  }
}
