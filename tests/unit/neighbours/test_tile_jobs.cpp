// The ordered tile jobs of tile_jobs.hpp: tiles within two of each other along every axis write to
// common particles, so the later one in tile order (x fastest, then y, then z) must start only after
// the earlier one has finished, on any number of threads; in two joined passes a tile is settled
// only after every tile within one has passed the first pass, and its second pass starts only after
// every tile within one is settled (and, among the second passes, in tile order again).
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <random>
#include <vector>

#include "neighbours/tile_jobs.hpp"
#include "parallel/loops.hpp"

namespace sphdisk {
namespace {

struct TileSet {
  std::array<int, 3> count;
  std::vector<char> busy;
  TileSet(std::array<int, 3> c, double fraction_busy, unsigned seed) : count(c) {
    busy.assign(static_cast<std::size_t>(c[0] * c[1] * c[2]), 0);
    std::mt19937 g(seed);
    std::bernoulli_distribution b(fraction_busy);
    for (auto& x : busy) x = b(g);
  }
  std::array<int, 3> coord(std::size_t t) const {
    return {static_cast<int>(t % static_cast<std::size_t>(count[0])),
            static_cast<int>(t / static_cast<std::size_t>(count[0]) % static_cast<std::size_t>(count[1])),
            static_cast<int>(t / static_cast<std::size_t>(count[0] * count[1]))};
  }
  bool within(std::size_t a, std::size_t b, int reach) const {
    const auto ca = coord(a), cb = coord(b);
    for (std::size_t k = 0; k < 3; ++k)
      if (std::abs(ca[k] - cb[k]) > reach) return false;
    return true;
  }
  // The tiles a job of tile t must wait for: busy tiles u within `reach` (earlier ones only when
  // earlier_only), t excluded.
  template <class F>
  void for_each_before(std::size_t t, int reach, bool earlier_only, F&& f) const {
    for (std::size_t u = 0; u < busy.size(); ++u)
      if (busy[u] && u != t && within(t, u, reach) && (!earlier_only || u < t)) f(u);
  }
};

// Work of varying length, so that the threads overtake each other where the schedule lets them.
void spin(std::size_t t) {
  volatile double x = 0;
  for (std::size_t k = 0; k < 200 + 1500 * (t * 2654435761u % 7); ++k) x = x + 1.0;
}

class Flags {
 public:
  explicit Flags(std::size_t n) : f_(std::make_unique<std::atomic<bool>[]>(n)) {
    for (std::size_t k = 0; k < n; ++k) f_[k].store(false);
  }
  bool operator[](std::size_t k) const { return f_[k].load(std::memory_order_acquire); }
  void set(std::size_t k) { f_[k].store(true, std::memory_order_release); }

 private:
  std::unique_ptr<std::atomic<bool>[]> f_;
};

const std::array<std::array<int, 3>, 4> kCounts{{{9, 7, 1}, {12, 3, 1}, {5, 4, 4}, {1, 11, 1}}};

TEST(TileJobs, TilesWithinTwoRunInTileOrderOnAnyThreadCount) {
  for (const auto& count : kCounts)
    for (double fraction : {0.6, 1.0}) {
      const TileSet s(count, fraction, 3);
      const TileJobs jobs(count, [&](std::size_t t) { return s.busy[t] != 0; });
      for (int threads : {1, 2, 4}) {
        par::set_threads(threads);
        Flags done(s.busy.size());
        std::atomic<int> violations{0}, runs{0};
        jobs.run_one_pass([&](std::uint32_t t) {
          s.for_each_before(t, 2, true, [&](std::size_t u) { violations += !done[u]; });
          spin(t);
          ++runs;
          done.set(t);
        });
        par::set_threads(0);
        int busy = 0;
        for (char b : s.busy) busy += b;
        EXPECT_EQ(runs.load(), busy) << "every busy tile once";
        EXPECT_EQ(violations.load(), 0) << threads << " threads, tiles " << count[0] << "x" << count[1] << "x" << count[2];
      }
    }
}

TEST(TileJobs, JoinedPassesWaitForTheirNeighbours) {
  for (const auto& count : kCounts) {
    const TileSet s(count, 0.7, 4);
    const TileJobs jobs(count, [&](std::size_t t) { return s.busy[t] != 0; });
    for (int threads : {1, 2, 4}) {
      par::set_threads(threads);
      Flags first_done(s.busy.size()), settled(s.busy.size()), second_done(s.busy.size());
      std::atomic<int> violations{0}, seconds{0};
      jobs.run_joined(
          [&](std::uint32_t t) {
            s.for_each_before(t, 2, true, [&](std::size_t u) { violations += !first_done[u]; });
            spin(t);
            first_done.set(t);
          },
          [&](std::uint32_t t) {
            violations += !first_done[t];
            s.for_each_before(t, 1, false, [&](std::size_t u) { violations += !first_done[u]; });
            settled.set(t);
          },
          [&](std::uint32_t t) {
            violations += !settled[t];
            s.for_each_before(t, 1, false, [&](std::size_t u) { violations += !settled[u]; });
            s.for_each_before(t, 2, true, [&](std::size_t u) { violations += !second_done[u]; });
            spin(t + 1);
            ++seconds;
            second_done.set(t);
          });
      par::set_threads(0);
      int busy = 0;
      for (char b : s.busy) busy += b;
      EXPECT_EQ(seconds.load(), busy);
      EXPECT_EQ(violations.load(), 0) << threads << " threads, tiles " << count[0] << "x" << count[1] << "x" << count[2];
    }
  }
}

}  // namespace
}  // namespace sphdisk
