// Half lists and their coloured schedule (neighbours/pair_lists.hpp): every pair with a writable
// particle exactly once, tiles of one colour never writing to the same particle, and each
// particle's pair terms in the same order for any thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <random>
#include <set>
#include <utility>

#include "neighbours/neighbour_lists.hpp"
#include "neighbours/pair_lists.hpp"
#include "parallel/loops.hpp"
#include "test_helpers.hpp"

using namespace sphdisk;

namespace {

// Gather lists as a run makes them: the first `listed` particles see every neighbour, the others
// (like ghosts or inactive particles) only listed ones; cells of radius/2 so that pairs reach over
// two cells; the half lists on tiles of `tile_cells` cells.
template <int D>
struct HalfListSetup {
  Particles<D> p;
  CellGrid<D> grid;
  NeighbourLists gather;
  PairLists pairs;
  std::vector<double> radii;  // each particle's gather radius, 2 h
  // unlisted_radius: the gather radius of the other particles (default: radius). spread: the
  // listed particles' radii vary at random by up to this fraction (as adaptive h does), so that
  // many pairs lie in one gather list only and some belong to their second particle.
  HalfListSetup(Particles<D> particles, double radius, std::size_t listed, int tile_cells, double unlisted_radius = 0,
                double spread = 0)
      : p(std::move(particles)) {
    const std::size_t n = p.size();
    if (unlisted_radius == 0) unlisted_radius = radius;
    radii.assign(n, unlisted_radius);
    std::vector<double> h(n);
    std::mt19937_64 g(5);
    std::uniform_real_distribution<double> u(-spread, spread);
    for (std::size_t i = 0; i < std::min(listed, n); ++i) radii[i] = radius * (1.0 + u(g));
    for (std::size_t i = 0; i < n; ++i) h[i] = 0.5 * radii[i];
    build_cell_grid(p.pos, p.id, 0.5 * radius, grid);
    build_tile_order(grid, tile_cells, listed, pairs, TileWrites::AllNeighbours);
    build_neighbour_lists(grid, p.pos, radii, gather, listed);
    append_neighbour_lists(grid, p.pos, listed, radii, gather, listed < n ? listed : SIZE_MAX);
    build_half_lists_from_gather(gather, p.pos, h, pairs);
  }
};

template <int D>
void check_every_pair_once(Particles<D> particles, double radius, std::size_t listed, int tile_cells,
                           bool expect_far, double unlisted_radius = 0, double spread = 0) {
  HalfListSetup<D> s(std::move(particles), radius, listed, tile_cells, unlisted_radius, spread);
  const std::size_t n = s.p.size();
  ASSERT_EQ(s.pairs.writable, listed);
  const auto radius_of = [&](std::uint32_t i) { return s.radii[i]; };
  std::set<std::pair<std::uint32_t, std::uint32_t>> expected, got;
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::uint32_t j = i + 1; j < n; ++j) {
      const double reach = std::max(radius_of(i), radius_of(j));
      if ((i < listed || j < listed) && norm2(s.p.pos[i] - s.p.pos[j]) < reach * reach) expected.insert({i, j});
    }
  // Recorded by pair number (calls run concurrently; each k is written once).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> visited(s.pairs.total(), {UINT32_MAX, UINT32_MAX});
  for_each_pair(s.pairs, [&](std::uint32_t i, std::uint32_t j, std::size_t k) { visited[k] = {std::min(i, j), std::max(i, j)}; });
  for (const auto& v : visited) got.insert(v);
  EXPECT_EQ(got.size(), visited.size()) << "a pair was visited twice, or a pair number skipped";
  EXPECT_EQ(got, expected);
  EXPECT_EQ(s.pairs.total(), expected.size());
  if (expect_far) EXPECT_GT(s.pairs.far.total(), 0u);
  else EXPECT_EQ(s.pairs.far.total(), 0u);
  EXPECT_GT(expected.size(), n);  // dense enough to mean something
}

// Pairs listed with their second particle in cell order (those only its gather list holds).
template <int D>
std::size_t pairs_owned_by_second(const HalfListSetup<D>& s) {
  std::size_t count = 0;
  for (const NeighbourLists* nl : {&s.pairs.near, &s.pairs.far})
    for (std::size_t k = 0; k < nl->size(); ++k)  // list k is particle order[k]'s
      for (const std::uint32_t* j = nl->begin(k); j != nl->end(k); ++j) count += s.pairs.slot[*j] < s.pairs.slot[s.pairs.order[k]];
  return count;
}

}  // namespace

TEST(PairLists, EveryPairOnce2D) { check_every_pair_once(test::random_particles<2>(1500, 11, true), 0.04, 1500, 2, false); }
TEST(PairLists, EveryPairOnce3D) { check_every_pair_once(test::random_particles<3>(1500, 12, false), 0.12, 1500, 2, false); }
// Radii that differ from particle to particle (adaptive h): a pair within only one particle's
// radius is listed once, by that particle, also where it comes second. Radii above the mean reach
// beyond the next tile, so there are far pairs too.
TEST(PairLists, EveryPairOnceWithVariableRadii) {
  check_every_pair_once(test::random_particles<2>(1500, 31, true), 0.04, 1500, 2, true, 0, 0.3);
  check_every_pair_once(test::random_particles<2>(1500, 32, true), 0.04, 1000, 2, true, 0.06, 0.3);
  check_every_pair_once(test::random_particles<2>(1500, 33, true), 0.04, 1500, 1, true, 0, 0.3);
  check_every_pair_once(test::random_particles<3>(1500, 34, false), 0.12, 1500, 2, true, 0, 0.3);
}

TEST(PairLists, EveryPairWithAListedParticleOnce) {
  check_every_pair_once(test::random_particles<2>(1500, 13, true), 0.04, 900, 4, false);
  check_every_pair_once(test::random_particles<3>(1500, 14, true), 0.08, 700, 2, false);
}
// Listed particles in one corner, as the active ones of a block timestep often are (the innermost
// orbits): the other particles' searches skip, by a count of listed particles per cell, those that
// have none within reach (neighbour_lists.cpp); the pairs must be the same. Particles are
// renumbered by x + y, so the first `listed` lie towards one corner; the unlisted ones reach
// 2.5x further, so the pairs across the boundary beyond the listed particles' radius come from
// the unlisted particles' searches only.
template <int D>
Particles<D> numbered_along_diagonal(Particles<D> p) {
  std::vector<std::uint32_t> order(p.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return p.pos[a][0] + p.pos[a][1] < p.pos[b][0] + p.pos[b][1]; });
  p.gather(order);
  return p;
}

TEST(PairLists, UnlistedParticlesFarFromListedOnesFindNothing) {
  check_every_pair_once(numbered_along_diagonal(test::random_particles<2>(3000, 17, true)), 0.02, 300, 8, false, 0.05);
  check_every_pair_once(numbered_along_diagonal(test::random_particles<2>(3000, 18, true)), 0.02, 1200, 1, true, 0.05);
}

// Tiles of one cell are narrower than the supports: pairs beyond the next tile become far pairs.
TEST(PairLists, PairsBeyondTheNextTileAreFarPairs) {
  check_every_pair_once(test::random_particles<2>(1500, 15, true), 0.04, 1500, 1, true);
  check_every_pair_once(test::random_particles<3>(1500, 16, false), 0.12, 1000, 1, true);
}

// Within a colour no two tiles write to the same particle (so they may run concurrently): the
// coloured schedule of half lists searched with one radius (TileWrites::Forward).
template <int D>
void check_colours_write_disjoint(Particles<D> p, double radius, int tile_cells) {
  const std::size_t n = p.size();
  CellGrid<D> grid;
  build_cell_grid(p.pos, p.id, 0.5 * radius, grid);
  PairLists pl;
  build_tile_order(grid, tile_cells, n, pl);
  build_half_neighbour_lists(grid, p.pos, radius, pl.slot, n, pl.order, pl.near);
  no_far_pairs(pl);
  ASSERT_EQ(pl.colour_start.size(), D == 2 ? 7u : 19u);
  ASSERT_EQ(pl.tiles_by_colour.size(), pl.colour_start.back());
  for (std::size_t c = 0; c + 1 < pl.colour_start.size(); ++c) {
    std::vector<int> writer(n, -1);
    for (std::size_t k = pl.colour_start[c]; k < pl.colour_start[c + 1]; ++k) {
      const int t = static_cast<int>(pl.tiles_by_colour[k]);
      for (std::size_t q = pl.tile_start[t]; q < pl.tile_start[t + 1]; ++q) {
        const std::uint32_t i = pl.order[q];
        for (const std::uint32_t* it = pl.near.begin(q); it != pl.near.end(q); ++it)  // list q is i's
          for (std::uint32_t x : {i, *it}) {
            ASSERT_TRUE(writer[x] == -1 || writer[x] == t) << "tiles " << writer[x] << " and " << t << " share particle " << x;
            writer[x] = t;
          }
      }
    }
  }
}

TEST(PairLists, TilesOfOneColourWriteToDisjointParticles) {
  // Cells of half the radius: tiles of two or more cells hold every pair in adjacent tiles (the
  // direct search has no far pairs; the run's tiles span 16 cells or more).
  for (int tile_cells : {2, 3}) check_colours_write_disjoint(test::random_particles<2>(3000, 17, true), 0.03, tile_cells);
  check_colours_write_disjoint(test::random_particles<3>(3000, 23, true), 0.08, 2);
}

// Half lists from gather lists (TileWrites::AllNeighbours) are not coloured: their tiles run as
// ordered jobs (tile_jobs.hpp, test_tile_jobs.cpp), which rely on every near pair joining particles
// of tiles within one of each other along every axis.
template <int D>
void check_near_pairs_in_adjacent_tiles(Particles<D> particles, double radius, int tile_cells, double spread) {
  const std::size_t n = particles.size();
  HalfListSetup<D> s(std::move(particles), radius, n, tile_cells, 0, spread);
  ASSERT_GT(pairs_owned_by_second(s), n / 10);  // pairs that write backwards
  const PairLists& pl = s.pairs;
  EXPECT_TRUE(pl.colour_start.empty());
  std::size_t pairs = 0;
  for (std::size_t q = 0; q < pl.order.size(); ++q) {
    const std::uint32_t i = pl.order[q];
    for (const std::uint32_t* it = pl.near.begin(q); it != pl.near.end(q); ++it, ++pairs)
      for (std::size_t k = 0; k < D; ++k)
        ASSERT_LE(std::abs(pl.tile[D * i + k] - pl.tile[D * *it + k]), 1) << "pair " << i << ", " << *it;
  }
  EXPECT_GT(pairs, n);
}

TEST(PairLists, NearPairsOfGatherListsLieInAdjacentTiles) {
  for (int tile_cells : {1, 2, 3}) check_near_pairs_in_adjacent_tiles(test::random_particles<2>(3000, 24, true), 0.03, tile_cells, 0.3);
  check_near_pairs_in_adjacent_tiles(test::random_particles<3>(3000, 25, true), 0.08, 2, 0.3);
}

// A sum whose bits depend on the order of its terms comes out the same on 1-4 threads.
TEST(PairLists, SameOrderOfPairTermsForAnyThreadCount) {
  // With far pairs, and pairs that belong to their second particle (radii vary by 30%).
  HalfListSetup<2> s(test::random_particles<2>(4000, 18, true), 0.03, 4000, 1, 0, 0.3);
  ASSERT_GT(s.pairs.far.total(), 0u);
  ASSERT_GT(pairs_owned_by_second(s), 400u);
  auto sums = [&](int threads) {
    par::set_threads(threads);
    std::vector<double> acc(s.p.size(), 0.0);
    for_each_pair(s.pairs, [&](std::uint32_t i, std::uint32_t j, std::size_t) {
      const double t = 1.0 / (1.0 + 1e3 * norm2(s.p.pos[i] - s.p.pos[j])) + 1e-9 * i;
      acc[i] = acc[i] * 0.999 + t;  // not associative: any change of order changes the bits
      acc[j] = acc[j] * 0.999 - t;
    });
    par::set_threads(0);
    return acc;
  };
  const auto one = sums(1);
  for (int threads : {2, 3, 4}) EXPECT_EQ(sums(threads), one) << threads << " threads";
}

// The direct search of half lists (constant radius): each pair with a writable particle once, in
// the list of the pair's first particle in cell order, scanning only the stencil after it.
template <int D>
void check_half_search(Particles<D> p, double radius, std::size_t writable) {
  CellGrid<D> grid;
  build_cell_grid(p.pos, p.id, 0.5 * radius, grid);
  PairLists pairs;
  build_tile_order(grid, 2, writable, pairs);
  build_half_neighbour_lists(grid, p.pos, radius, pairs.slot, writable, pairs.order, pairs.near);
  no_far_pairs(pairs);
  const std::size_t n = p.size();
  ASSERT_EQ(pairs.near.size(), n);
  std::vector<std::size_t> list_of(n);  // lists are in tile order: list s is particle order[s]'s
  for (std::size_t s = 0; s < n; ++s) list_of[pairs.order[s]] = s;
  std::size_t expected = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    std::vector<std::uint32_t> brute;
    for (std::uint32_t j = 0; j < n; ++j)
      if (j != i && pairs.slot[j] > pairs.slot[i] && (i < writable || j < writable) &&
          norm2(p.pos[i] - p.pos[j]) < radius * radius)
        brute.push_back(j);
    std::vector<std::uint32_t> got(pairs.near.begin(list_of[i]), pairs.near.end(list_of[i]));
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, brute) << "particle " << i;
    expected += brute.size();
  }
  EXPECT_GT(expected, n);
}

TEST(PairLists, HalfSearchEqualsBruteForce) {
  check_half_search(test::random_particles<2>(2000, 19, true), 0.03, 2000);
  check_half_search(test::random_particles<2>(2000, 20, false), 0.05, 1200);
  check_half_search(test::random_particles<3>(2000, 21, true), 0.06, 2000);
  check_half_search(test::random_particles<3>(2000, 22, false), 0.12, 900);
}

// Gather lists left in the search's blocks (build_settled_neighbour_lists with join = false) read
// the same through list(i) as once joined, and give the same half lists: the run's path (lists
// read in their blocks) against the joined one. 5,000 particles: ten blocks.
TEST(PairLists, GatherListsReadInTheirBlocksEqualJoinedOnes) {
  const auto p = test::random_particles<2>(5000, 41, true);
  const auto grid = build_cell_grid(p.pos, p.id, 0.02);
  std::vector<double> radius(p.size()), h(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    radius[i] = 0.03 + 0.02 * static_cast<double>(i % 7) / 7.0;
    h[i] = 0.4 * radius[i];
  }
  const SettleRadius settle = [](std::size_t, std::span<const std::uint32_t>, std::span<const double>, double searched) {
    return 0.8 * searched;  // drop the outer candidates (lists of varying length in each block)
  };
  NeighbourLists blocked, joined;
  build_settled_neighbour_lists(grid, p.pos, radius, settle, blocked, p.size(), false);
  build_settled_neighbour_lists(grid, p.pos, radius, settle, joined, p.size());
  ASSERT_FALSE(blocked.joined);
  ASSERT_TRUE(joined.joined);
  ASSERT_GT(p.size(), 4 * NeighbourLists::kBlock);
  EXPECT_EQ(blocked.offsets, joined.offsets);
  EXPECT_GT(joined.total(), 10 * p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto a = blocked.list(i), b = joined.list(i);
    ASSERT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end())) << "particle " << i;
  }
  auto half_lists = [&](NeighbourLists& gather) {
    PairLists pairs;
    build_tile_order(grid, 4, p.size(), pairs, TileWrites::AllNeighbours);
    build_half_lists_from_gather(gather, p.pos, h, pairs);
    return pairs;
  };
  const PairLists from_blocked = half_lists(blocked), from_joined = half_lists(joined);
  EXPECT_EQ(from_blocked.near.offsets, from_joined.near.offsets);
  for (std::size_t s = 0; s < p.size(); ++s) {
    const auto a = from_blocked.near.list(s), b = from_joined.near.list(s);
    ASSERT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end())) << "list " << s;
  }
  EXPECT_EQ(from_blocked.far.index, from_joined.far.index);
  blocked.join();
  EXPECT_TRUE(blocked.joined);
  EXPECT_EQ(blocked.index, joined.index);
}

// Gather lists searched in the tile order (list s: particle order[s]'s) give the half lists of the
// gather lists in particle order, entry for entry (left inside the gather lists instead of copied
// into place), and so does joining them. Some particles unwritable and tiles of 2 cells, so that far
// lists and dropped pairs occur; the second build reuses the first one's blocks with other radii.
TEST(PairLists, HalfListsFromGatherListsInTileOrder) {
  const auto p = test::random_particles<2>(5000, 43, true);
  const auto grid = build_cell_grid(p.pos, p.id, 0.02);
  const SettleRadius keep_all = [](std::size_t, std::span<const std::uint32_t>, std::span<const double>, double searched) {
    return searched;
  };
  PairLists reused;
  for (const double spread : {0.02, 0.035}) {
    std::vector<double> radius(p.size()), h(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
      radius[i] = 0.025 + spread * static_cast<double>(i % 7) / 7.0;
      h[i] = 0.5 * radius[i];
    }
    const std::size_t writable = p.size() * 3 / 4;
    PairLists by_particle;
    build_tile_order(grid, 2, writable, by_particle, TileWrites::AllNeighbours);
    NeighbourLists gather, gather_tiled;
    build_settled_neighbour_lists(grid, p.pos, radius, keep_all, gather, p.size());
    build_half_lists_from_gather(gather, p.pos, h, by_particle);
    build_tile_order(grid, 2, writable, reused, TileWrites::AllNeighbours);
    build_settled_neighbour_lists(grid, p.pos, radius, keep_all, gather_tiled, p.size(), false, reused.order.data());
    build_half_lists_from_gather(gather_tiled, p.pos, h, reused, true);
    EXPECT_EQ(reused.near.within, &gather_tiled);  // read inside the gather lists
    EXPECT_TRUE(reused.near.index.empty() && reused.near.block_index.empty());  // no copy held
    EXPECT_EQ(reused.order, by_particle.order);
    EXPECT_EQ(reused.near.offsets, by_particle.near.offsets);
    EXPECT_EQ(reused.far.offsets, by_particle.far.offsets);
    EXPECT_GT(by_particle.near.total(), 5 * p.size());
    EXPECT_GT(by_particle.far.total(), 100u);  // far lists exercised
    for (std::size_t s = 0; s < p.size(); ++s) {
      const auto a = reused.near.list(s), b = by_particle.near.list(s);
      ASSERT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end())) << "list " << s;
    }
    EXPECT_EQ(reused.far.index, by_particle.far.index);
    reused.near.join();
    by_particle.near.join();
    EXPECT_EQ(reused.near.within, nullptr);
    EXPECT_EQ(reused.near.index, by_particle.near.index);
  }
}
