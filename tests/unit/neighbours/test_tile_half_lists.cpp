// Half lists searched on the pair loops' coloured schedule (neighbours/tile_half_lists.hpp): the
// lists of the block search (the same partners in the same order), each handed to its visit with
// the exact squared distances and room for its factors, which the pair loops then read back; and
// the density summed so during the search gives the separate density loop's rates bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <vector>

#include "evaluate/rate_evaluator.hpp"
#include "neighbours/neighbour_lists.hpp"
#include "neighbours/pair_lists.hpp"
#include "neighbours/tile_half_lists.hpp"
#include "parallel/loops.hpp"
#include "test_helpers.hpp"

using namespace sphdisk;

namespace {

template <int D>
void check_same_lists(Particles<D> p, double radius, std::size_t writable, int threads) {
  SCOPED_TRACE(std::to_string(D) + "D, " + std::to_string(writable) + " writable, " + std::to_string(threads) + " threads");
  par::set_threads(threads);
  CellGrid<D> grid;
  build_cell_grid(p.pos, p.id, 0.5 * radius, grid);
  PairLists blocks, tiles;
  build_tile_order(grid, 2, writable, blocks);
  build_half_neighbour_lists(grid, p.pos, radius, blocks.slot, writable, blocks.order, blocks.near);
  build_tile_order(grid, 2, writable, tiles);
  TileFactors factors;
  std::atomic<std::size_t> visits{0}, wrong_distances{0};
  build_half_lists_on_tiles(grid, p.pos, radius, tiles, factors,
                            [&](std::uint32_t i, std::span<const std::uint32_t> js, std::span<const double> d2, std::span<float> F) {
                              ++visits;
                              for (std::size_t q = 0; q < js.size(); ++q) {
                                if (d2[q] != norm2(p.pos[i] - p.pos[js[q]])) ++wrong_distances;
                                F[q] = static_cast<float>(i) + 1e-3f * static_cast<float>(js[q] % 1000);
                              }
                            });
  par::set_threads(0);
  const std::size_t n = p.size();
  ASSERT_EQ(tiles.near.size(), n);
  EXPECT_EQ(tiles.far.total(), 0u);
  EXPECT_EQ(tiles.near.total(), blocks.near.total());
  EXPECT_GT(tiles.near.total(), n);  // dense enough to mean something
  EXPECT_EQ(wrong_distances.load(), 0u);
  std::size_t non_empty = 0;
  for (std::size_t s = 0; s < n; ++s) {
    const std::span<const std::uint32_t> a = blocks.near.list(s), b = tiles.near.list(s);
    ASSERT_EQ(std::vector<std::uint32_t>(b.begin(), b.end()), std::vector<std::uint32_t>(a.begin(), a.end())) << "list " << s;
    non_empty += b.empty() ? 0 : 1;
  }
  EXPECT_EQ(visits.load(), non_empty);
  // The pair loops read each list with the factors its visit wrote.
  std::atomic<std::size_t> read{0};
  TiledPairs{tiles, factors}.for_each_list([&](std::uint32_t i, std::span<const std::uint32_t> js, std::span<float> F) {
    for (std::size_t q = 0; q < js.size(); ++q)
      ASSERT_EQ(F[q], static_cast<float>(i) + 1e-3f * static_cast<float>(js[q] % 1000));
    read += js.size();
  }, FactorUse::Read);
  EXPECT_EQ(read.load(), tiles.near.total());
  // Joined, they are the block search's lists too.
  tiles.near.join();
  for (std::size_t s = 0; s < n; s += 97) EXPECT_TRUE(std::ranges::equal(tiles.near.list(s), blocks.near.list(s)));
}

}  // namespace

TEST(TileHalfLists, TheBlockSearchsListsWithExactDistances) {
  for (int threads : {1, 2}) {
    check_same_lists(test::random_particles<2>(3000, 31, true), 0.03, 3000, threads);
    check_same_lists(test::random_particles<2>(3000, 32, false), 0.05, 1700, threads);
    check_same_lists(test::random_particles<3>(2000, 33, true), 0.08, 2000, threads);
  }
}

// With one smoothing length the density is summed during the search by default; the separate
// density loop over the stored lists is the reference: the same rho, stress and accelerations, bit
// for bit, for every kernel and on 1 and 3 threads.
TEST(TileHalfLists, DensitySummedDuringTheSearchGivesTheSameRates) {
  for (KernelType kernel : {KernelType::Cubic, KernelType::WendlandC2, KernelType::WendlandC4})
    for (int threads : {1, 3}) {
      Particles<2> in_search = test::random_particles<2>(3000, 7, true), in_loop = in_search;
      for (auto* p : {&in_search, &in_loop})
        for (std::size_t i = 0; i < p->size(); ++i) p->vel[i] = Vec<2>{{-p->pos[i][1], p->pos[i][0] * p->pos[i][0]}};
      PhysicsParams phys;
      phys.nu = 0.01;
      par::set_threads(threads);
      for (bool summed : {true, false}) {
        PhaseTimers timers;
        RateEvaluator<2> rates(kernel, 0.012, phys, timers);
        rates.set_density_in_search(summed);
        rates.evaluate(summed ? in_search : in_loop);
        const auto& phases = timers.phases();
        const bool traced = std::ranges::any_of(phases, [](const auto& ph) { return ph.first == "search_and_density"; });
        EXPECT_EQ(traced, summed);
      }
      par::set_threads(0);
      for (std::size_t i = 0; i < in_search.size(); ++i) {
        ASSERT_EQ(in_search.rho[i], in_loop.rho[i]) << i;
        ASSERT_EQ(in_search.acc[i], in_loop.acc[i]) << i;
        for (std::size_t c = 0; c < 4; ++c) ASSERT_EQ(in_search.stress[i].c[c], in_loop.stress[i].c[c]) << i;
      }
    }
}
