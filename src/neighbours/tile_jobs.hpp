#pragma once
// The order in which pair loops visit tiles that write to every adjacent tile
// (pair_lists.hpp: TileWrites::AllNeighbours), and the jobs that keep it on threads.
//
// Order: a particle receives its pair terms tile by tile in tile order (x fastest, then y, then z),
// inside a tile in the tile's particle order. Two tiles write to a common particle only if they lie
// within two tiles of each other along every axis; such tiles are joined by a dependency (the later
// one waits, par::for_each_after), so the order holds for any thread count and, as tiles are blocks
// of the shared lattice, for any rank count. Jobs are taken along the wavefront x + 3 y + 9 z, which
// orders every two such tiles as tile order does (|dx|, |dy| <= 2: dx + 3 dy + 9 dz > 0 exactly when
// the second comes later), while tiles on one front are independent and run side by side.
//
// Two loops joined (run_joined): the velocity-gradient pass, then each tile's particles settled
// (stress from their sums) once every tile writing to them has passed, then the force pass of a
// tile once its partners' tiles are settled. A tile's force pass follows its gradient pass by about
// two rows of tiles, so what the gradient pass found (its pair lists) need be kept only for the
// tiles in between (pair_scan.hpp), not for all: the search is done once for both loops.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "parallel/loops.hpp"

namespace sphdisk {

class TileJobs {
 public:
  // count: tiles per dimension (PairLists::tile_count); busy(t): whether tile t has any work (idle
  // and empty tiles get no job).
  template <class Busy>
  TileJobs(const std::array<int, 3>& count, Busy&& busy) : count_(count) {
    const std::size_t ntiles = static_cast<std::size_t>(count[0]) * static_cast<std::size_t>(count[1]) * static_cast<std::size_t>(count[2]);
    job_.assign(ntiles, kNone);
    for (std::size_t t = 0; t < ntiles; ++t)
      if (busy(t)) busy_.push_back(static_cast<std::uint32_t>(t));
    std::stable_sort(busy_.begin(), busy_.end(), [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
    for (std::size_t k = 0; k < busy_.size(); ++k) job_[busy_[k]] = static_cast<std::uint32_t>(k);
    for (int k = 0, w = 1; k < 3; ++k, w *= 3)
      if (count_[static_cast<std::size_t>(k)] > 1) reach1_ += w;  // largest key step to a tile within one
  }

  // run(t) for every busy tile, in the order above.
  template <class Run>
  void run_one_pass(Run&& run, std::string_view trace_label = {}) const {
    par::for_each_after(busy_.size(), [&](std::size_t k, const auto& need) {
      const std::uint32_t t = busy_[k];
      around(t, 2, [&](std::uint32_t u) {
        if (key(u) < key(t)) need(job_[u]);
      });
    }, [&](std::size_t k) { run(busy_[k]); }, trace_label);
  }

  // first(t) for every busy tile in the order above; settle(t) once every tile within one of t has
  // passed first(); second(t) once every tile within one of t is settled, in the order above.
  template <class First, class Settle, class Second>
  void run_joined(First&& first, Settle&& settle, Second&& second, std::string_view trace_label = {}) const {
    // Jobs 3 k + pass, taken in the order of their wavefront positions: a settle job at its tile's
    // position + reach1_ (after the last first() it needs), a second() job at + 2 reach1_.
    std::vector<std::uint32_t> jobs(3 * busy_.size());
    for (std::size_t j = 0; j < jobs.size(); ++j) jobs[j] = static_cast<std::uint32_t>(j);
    const auto position = [&](std::uint32_t j) { return key(busy_[j / 3]) + static_cast<long>(j % 3) * reach1_; };
    std::stable_sort(jobs.begin(), jobs.end(), [&](std::uint32_t a, std::uint32_t b) {
      const long pa = position(a), pb = position(b);
      return pa != pb ? pa < pb : a % 3 < b % 3;
    });
    std::vector<std::uint32_t> taken(jobs.size());  // job 3 k + pass is taken taken[...]-th
    for (std::size_t n = 0; n < jobs.size(); ++n) taken[jobs[n]] = static_cast<std::uint32_t>(n);
    const auto at = [&](std::uint32_t t, int pass) { return taken[3 * std::size_t{job_[t]} + static_cast<std::size_t>(pass)]; };
    par::for_each_after(jobs.size(), [&](std::size_t n, const auto& need) {
      const std::uint32_t t = busy_[jobs[n] / 3];
      switch (jobs[n] % 3) {
        case 0: around(t, 2, [&](std::uint32_t u) { if (key(u) < key(t)) need(at(u, 0)); }); break;
        case 1: around(t, 1, [&](std::uint32_t u) { need(at(u, 0)); }); break;
        default:
          around(t, 1, [&](std::uint32_t u) { need(at(u, 1)); });
          around(t, 2, [&](std::uint32_t u) { if (key(u) < key(t)) need(at(u, 2)); });
      }
    }, [&](std::size_t n) {
      const std::uint32_t t = busy_[jobs[n] / 3];
      switch (jobs[n] % 3) {
        case 0: first(t); break;
        case 1: settle(t); break;
        default: second(t);
      }
    }, trace_label);
  }

 private:
  static constexpr std::uint32_t kNone = UINT32_MAX;

  std::array<int, 3> coord(std::uint32_t t) const {
    return {static_cast<int>(t % static_cast<std::uint32_t>(count_[0])),
            static_cast<int>(t / static_cast<std::uint32_t>(count_[0]) % static_cast<std::uint32_t>(count_[1])),
            static_cast<int>(t / static_cast<std::uint32_t>(count_[0] * count_[1]))};
  }
  long key(std::uint32_t t) const {
    const auto c = coord(t);
    return c[0] + 3L * c[1] + 9L * c[2];
  }
  // f(u) for every busy tile u within `reach` tiles of t along every axis (t itself included).
  template <class F>
  void around(std::uint32_t t, int reach, F&& f) const {
    const auto c = coord(t);
    std::array<int, 3> lo{}, hi{};
    for (std::size_t k = 0; k < 3; ++k) {
      lo[k] = std::max(0, c[k] - reach);
      hi[k] = std::min(count_[k] - 1, c[k] + reach);
    }
    for (int z = lo[2]; z <= hi[2]; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y)
        for (int x = lo[0]; x <= hi[0]; ++x) {
          const auto u = static_cast<std::uint32_t>(x + count_[0] * (y + count_[1] * z));
          if (job_[u] != kNone) f(u);
        }
  }

  std::array<int, 3> count_;
  std::vector<std::uint32_t> busy_;  // busy tiles, in wavefront order
  std::vector<std::uint32_t> job_;   // per tile: its place in busy_, or kNone
  long reach1_ = 0;
};

}  // namespace sphdisk
