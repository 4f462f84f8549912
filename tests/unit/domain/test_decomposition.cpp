// Two-level domain decomposition (domain/decomposition.hpp): balance and determinism, without MPI.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include "domain/decomposition.hpp"
#include "domain/distributed_domain.hpp"
#include "test_helpers.hpp"

using namespace sphdisk;

TEST(Decomposition, MortonKeyInterleavesBits) {
  EXPECT_EQ(morton_key<2>({0, 0}), 0u);
  EXPECT_EQ(morton_key<2>({1, 0}), 1u);
  EXPECT_EQ(morton_key<2>({0, 1}), 2u);
  EXPECT_EQ(morton_key<2>({3, 3}), 15u);
  EXPECT_EQ(morton_key<3>({1, 1, 1}), 7u);
  EXPECT_EQ(morton_key<3>({2, 0, 0}), 8u);
}

TEST(Decomposition, EqualCountsPerRankWithinOneTopCell) {
  const Particles<2> p = test::random_particles<2>(20000, 7, true);
  Vec<2> lo, hi;
  bounding_box(p.pos, lo, hi);
  for (int ranks : {1, 2, 3, 4, 7}) {
    Decomposition<2> d = make_top_grid(make_lattice(lo, hi, p.size(), 0.01), 256 * static_cast<std::size_t>(ranks));
    std::vector<std::uint64_t> counts(d.top_cells(), 0);
    for (const auto& x : p.pos) ++counts[d.top_cell_of(x)];
    assign_owners(d, counts, ranks);
    std::vector<std::uint64_t> per_rank(static_cast<std::size_t>(ranks), 0);
    for (std::size_t c = 0; c < d.top_cells(); ++c) per_rank[static_cast<std::size_t>(d.owner[c])] += counts[c];
    const std::uint64_t heaviest_cell = *std::max_element(counts.begin(), counts.end());
    const double share = static_cast<double>(p.size()) / ranks;
    for (int r = 0; r < ranks; ++r)
      EXPECT_LE(std::abs(static_cast<double>(per_rank[static_cast<std::size_t>(r)]) - share), static_cast<double>(heaviest_cell))
          << ranks << " ranks, rank " << r;
    // Every particle's top cell contains it (distance 0 to its own box).
    for (const auto& x : p.pos) ASSERT_EQ(d.distance2_to(x, d.top_coord(x)), 0.0);
  }
}

TEST(Decomposition, OneRankMigrationAndHaloChangeNothing) {
  Particles<2> p = test::random_particles<2>(3000, 3, false);
  const Particles<2> before = p;
  const Communicator comm = Communicator::world();
  if (comm.size() != 1) GTEST_SKIP() << "runs on one rank";
  const Decomposition<2> d = decompose(comm, p, 0.02);
  migrate(comm, d, p);
  Halo<2> halo;
  const auto radius = [](std::size_t) { return 0.04; };
  halo.build(comm, d, p, radius, radius);
  EXPECT_EQ(halo.ghosts(), 0u);
  EXPECT_EQ(p.id, before.id);
  EXPECT_EQ(p.pos, before.pos);
}
