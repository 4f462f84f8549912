#pragma once
// Pair loops without stored lists (sph.pair_lists = "rescan"): each pair loop finds every
// particle's partners anew in the cell grid, as SWIFT does, so no neighbour list or pair factor is
// kept (the lists and their factors are most of the memory of a run with stored lists,
// docs/performance.md, "Memory per particle"); the price is the search repeated by the loops and
// the kernel gradient recomputed for every pair. The velocity-gradient and force loops can share
// one search (for_each_list_joined): a tile's lists are kept from its gradient pass to its force
// pass, about two tile rows later (tile_jobs.hpp), so only the tiles in between hold lists.
//
// Each pair with |x_i - x_j| < 2 max(h_i, h_j) and a writable particle is evaluated once, by its
// owner: the first particle in cell order when the pair lies within its own support 2 h, else the
// second (then it lies within the second's support). So every particle finds the pairs it owns
// within its own support radius and no transposition is needed; but an owner may write to a
// partner before it, in any adjacent tile, so the tiles are scheduled for writes to all their
// neighbours (TileWrites::AllNeighbours, pair_lists.hpp; tile_jobs.hpp). Pairs whose tiles are not
// adjacent (a support wider than a tile) are evaluated before or after all tiles, in tile order.
// Each particle thus gets its pair terms in an order fixed by positions, IDs, smoothing lengths and
// the lattice: the same bits for any thread or rank count. With adaptive h these are also the stored lists' owners,
// schedule and partner order, so the two give the same bits (test_pair_scan.cpp); with one smoothing
// length for all particles the owner is always the first, only the half of the stencil after it is
// searched, and the stored lists' forward-only schedule orders the terms differently (round-off).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "core/vec.hpp"
#include "neighbours/candidate_filter.hpp"
#include "neighbours/candidate_ranges.hpp"
#include "neighbours/candidate_scan.hpp"
#include "neighbours/cell_grid.hpp"
#include "neighbours/pair_lists.hpp"
#include "neighbours/tile_jobs.hpp"
#include "parallel/loops.hpp"

namespace sphdisk {

// tiles: the tile order of build_tile_order(..., TileWrites::AllNeighbours) over `grid` (its near
// and far lists unused). h: every grid particle's smoothing length (support 2 h); equal_h: all the
// same. writable: CandidateFilter::build over `grid` for tiles.writable, so that an unwritable
// particle without writable particles within reach is skipped before its rows are formed, and skips
// rows of cells without writable partners. form(i, js, r2, factors) writes the kernel-gradient factors of
// the pairs (i, js[q]) at squared distances r2[q] (physics/list_factors.hpp), for the loops that
// read factors.
template <int D, class Form>
class ScannedPairs {
 public:
  ScannedPairs(const CellGrid<D>& grid, const PairLists& tiles, const std::vector<double>& h, bool equal_h,
               const CandidateFilter& writable, Form form)
      : grid_(grid), tiles_(tiles), h_(h), equal_h_(equal_h), writable_(writable), form_(form) {
    if (!writable_.slot_prefix.empty())
      for (std::size_t i = 0; i < tiles_.writable; ++i) widest_writable_h_ = std::max(widest_writable_h_, h_[i]);
    summarise_tiles();  // (before the loops: may_read reads the summary)
  }

  // Whether a loop may read particle i: writable, or within reach of a writable particle, as a pair
  // lies within the support of one of its two (2 max(h_i, h_j) <= 2 max(h_i, the widest writable h)).
  // Answered from a mask the tiles' summary fills (summarise_tiles), a little wider than that test.
  bool may_read(std::uint32_t i) const {
    return i < tiles_.writable || writable_.slot_prefix.empty() || may_read_[i] != 0;
  }

  static constexpr bool kJoinsLoops = true;  // for_each_list_joined (physics/viscous_rates.hpp)
  std::size_t writable() const { return tiles_.writable; }
  void prepare_factors() const {}
  // Pairs found by the first loop (every loop finds the same ones): the pair count of an evaluation.
  std::size_t pairs_found() const { return found_.load(); }

  // The interface of StoredPairs (pair_lists.hpp): f(i, js, F) for every particle owning pairs, in
  // the order of tile_jobs.hpp, the far pairs before or after the tiles' pairs.
  template <class F>
  void for_each_list(F&& f, FactorUse use, std::string_view trace_label = {}, FarPairs far_pairs = FarPairs::Last) const {
    const bool count = begin_loop();
    const auto visit = [&](std::uint32_t i, bool far) { return visit_particle(i, far, use, count, f); };
    if (far_pairs == FarPairs::First) visit_far(visit, count);
    jobs_->run_one_pass([&](std::uint32_t t) {
      std::size_t pairs = 0;
      for (std::size_t s = tiles_.tile_start[t]; s < tiles_.tile_start[t + 1]; ++s) pairs += visit(tiles_.order[s], false);
      if (count) found_ += pairs;
    }, trace_label);
    if (far_pairs == FarPairs::Last) visit_far(visit, count);
  }

  // Two loops in one pass (TileJobs::run_joined): first(i, js, F) for every list as for_each_list
  // with FarPairs::First gives them, settle(i) for every writable particle once every pair term of
  // the first loop has reached it, and second(i, js, F) for every list as for_each_list with
  // FarPairs::Last gives them, a tile's lists as soon as its partners' tiles are settled. Each
  // tile's lists (partners and factors) are kept from its first pass to its second, so the pairs are
  // searched once for both loops, while only the tiles between the two passes hold lists (about two
  // rows of tiles) rather than every particle (the memory that sph.pair_lists = "rescan" saves).
  template <class First, class Settle, class Second>
  void for_each_list_joined(First&& first, Settle&& settle, Second&& second, std::string_view trace_label = {}) const {
    const bool count = begin_loop();
    const std::size_t m = tiles_.writable;
    KeptLists far_kept;
    std::vector<KeptLists> kept(tiles_.tile_start.size() - 1);
    const auto keep_then = [&](KeptLists& into, std::uint32_t i, bool far) {
      return visit_particle(i, far, FactorUse::Read, count, [&](std::uint32_t i_, std::span<const std::uint32_t> js, std::span<float> F) {
        into.add(i_, js, F);
        first(i_, js, F);
      });
    };
    visit_far([&](std::uint32_t i, bool far) { return keep_then(far_kept, i, far); }, count);
    jobs_->run_joined([&](std::uint32_t t) {
      // Written where they grow on this thread, then kept at their size (growing each tile's own
      // lists would move them as they grow and leave them up to twice their size).
      thread_local KeptLists growing;
      growing.clear();
      std::size_t pairs = 0;
      for (std::size_t s = tiles_.tile_start[t]; s < tiles_.tile_start[t + 1]; ++s) pairs += keep_then(growing, tiles_.order[s], false);
      kept[t].copy(growing);
      if (count) found_ += pairs;
    }, [&](std::uint32_t t) {
      for (std::size_t s = tiles_.tile_start[t]; s < tiles_.tile_start[t + 1]; ++s)
        if (tiles_.order[s] < m) settle(tiles_.order[s]);
    }, [&](std::uint32_t t) {
      kept[t].replay(second);
      kept[t] = {};  // freed: the memory stays bounded by the tiles in flight
    }, trace_label);
    far_kept.replay(second);
  }

 private:
  // The lists of a tile, kept from one loop to the next: (i, n, partners) runs and their factors.
  struct KeptLists {
    std::vector<std::uint32_t> lists;
    std::vector<float> factors;
    void add(std::uint32_t i, std::span<const std::uint32_t> js, std::span<const float> F) {
      lists.push_back(i);
      lists.push_back(static_cast<std::uint32_t>(js.size()));
      lists.insert(lists.end(), js.begin(), js.end());
      factors.insert(factors.end(), F.begin(), F.end());
    }
    template <class F>
    void replay(F& f) {
      float* at = factors.data();
      for (std::size_t k = 0; k < lists.size();) {
        const std::uint32_t i = lists[k], n = lists[k + 1];
        f(i, std::span<const std::uint32_t>(lists.data() + k + 2, n), std::span<float>(at, n));
        at += n;
        k += 2 + std::size_t{n};
      }
    }
    void clear() {
      lists.clear();
      factors.clear();
    }
    void copy(const KeptLists& o) {
      lists.assign(o.lists.begin(), o.lists.end());
      factors.assign(o.factors.begin(), o.factors.end());
    }
  };

  // Whether this loop is the first (it counts the pairs and notes their owners); summarises the
  // tiles and schedules them once per evaluation.
  bool begin_loop() const {
    const bool count = !counted_;  // in the first loop only: one atomic add per tile, not per list
    counted_ = true;                // (per list, threads would contend for the counter's cache line)
    return count;
  }

  // The first loop notes which particles own a pair (each particle is visited by one thread); the
  // loops after it skip the others, whose tests and scans would find the same nothing
  // (docs/performance.md, "Block timesteps").
  template <class F>
  std::size_t visit_particle(std::uint32_t i, bool far, FactorUse use, bool count, F&& f) const {
    if (!count && !owns_pairs_[i]) return 0;
    const std::size_t found = list_of(i, far, use, f);
    if (count) owns_pairs_[i] |= static_cast<char>(found > 0);
    return found;
  }

  // Far pairs: serial, in tile order, in the tiles that hold a particle reaching beyond the
  // adjacent tiles only (a serial test of every particle in each loop would keep the other threads
  // idle).
  template <class Visit>
  void visit_far(Visit&& visit, bool count) const {
    std::size_t far_pairs = 0;
    for (std::size_t t = 0; t < far_tile_.size(); ++t) {
      if (!far_tile_[t]) continue;
      for (std::size_t s = tiles_.tile_start[t]; s < tiles_.tile_start[t + 1]; ++s) {
        const std::uint32_t i = tiles_.order[s];
        if (reach_of(i) > tiles_.tile_cells) far_pairs += visit(i, true);
      }
    }
    if (count) found_ += far_pairs;
  }

  int reach_of_h(double h) const { return cells_within(grid_, 2.0 * h); }
  int reach_of(std::size_t i) const { return reach_of_h(h_[i]); }

  // Once per evaluation (h does not change between the loops), in parallel, for each tile: whether
  // a particle of it reaches beyond the adjacent tiles (far_tile_), whether none of them can own a
  // pair (idle_tile_: no writable particle in it and none within the widest support of its
  // particles' bounding box), and which particles a loop may read (may_read_: a writable particle
  // within 2 max(h, the widest writable h) of the tile, then of each run of kReadRun particles in
  // tile order, which lie close together: one test per run, not per particle). With block
  // timesteps most tiles lie far from every active particle, and a test of each of their particles
  // in every loop would be a large part of an evaluation with few active (docs/performance.md,
  // "Block timesteps").
  void summarise_tiles() {
    const std::size_t ntiles = tiles_.tile_start.size() - 1, m = tiles_.writable;
    const bool filtered = !writable_.slot_prefix.empty();
    far_tile_.assign(ntiles, 0);
    idle_tile_.assign(ntiles, 0);
    may_read_.assign(filtered ? tiles_.order.size() : 0, 0);
    owns_pairs_.assign(tiles_.order.size(), 0);
    par::for_each(ntiles, [&](std::size_t t) {
      const std::size_t s0 = tiles_.tile_start[t], s1 = tiles_.tile_start[t + 1];
      if (s0 == s1) return;
      const auto [lo, hi, widest] = extent_of(s0, s1);
      const bool writable = std::any_of(tiles_.order.begin() + static_cast<std::ptrdiff_t>(s0),
                                        tiles_.order.begin() + static_cast<std::ptrdiff_t>(s1),
                                        [m](std::uint32_t i) { return i < m; });
      far_tile_[t] = reach_of_h(widest) > tiles_.tile_cells;
      idle_tile_[t] = filtered && !writable && !writable_.any_within_box(grid_, lo, hi, 2.0 * widest);
      if (filtered && (writable || writable_.any_within_box(grid_, lo, hi, 2.0 * std::max(widest, widest_writable_h_))))
        mark_read_runs(s0, s1);
    }, {}, 1);
    jobs_.emplace(tiles_.tile_count, [&](std::size_t t) { return tiles_.tile_start[t + 1] > tiles_.tile_start[t] && !idle_tile_[t]; });
  }

  // The bounding box and the largest h of the particles order[s0 .. s1) (s0 < s1).
  struct Extent {
    Vec<D> lo, hi;
    double widest;
  };
  Extent extent_of(std::size_t s0, std::size_t s1) const {
    Extent e{grid_.sorted_pos[tiles_.slot[tiles_.order[s0]]], grid_.sorted_pos[tiles_.slot[tiles_.order[s0]]], 0.0};
    for (std::size_t s = s0; s < s1; ++s) {
      const std::uint32_t i = tiles_.order[s];
      const Vec<D>& x = grid_.sorted_pos[tiles_.slot[i]];
      for (int k = 0; k < D; ++k) {
        e.lo[k] = std::min(e.lo[k], x[k]);
        e.hi[k] = std::max(e.hi[k], x[k]);
      }
      e.widest = std::max(e.widest, h_[i]);
    }
    return e;
  }

  // may_read_ for the particles order[s0 .. s1) of a tile some writable particle may reach: run by run.
  void mark_read_runs(std::size_t s0, std::size_t s1) {
    constexpr std::size_t kReadRun = 8;
    for (std::size_t r0 = s0; r0 < s1; r0 += kReadRun) {
      const std::size_t r1 = std::min(s1, r0 + kReadRun);
      const auto [lo, hi, widest] = extent_of(r0, r1);
      if (!writable_.any_within_box(grid_, lo, hi, 2.0 * std::max(widest, widest_writable_h_))) continue;
      for (std::size_t s = r0; s < r1; ++s) may_read_[tiles_.order[s]] = 1;
    }
  }

  // i's pairs in adjacent tiles (far = false) or in tiles farther away (far = true), in cell order:
  // its candidates within its support scanned row by row (scan_row: vectorised in 2D), each row
  // range split at i's own slot, so that the candidates before i in cell order come first; of those,
  // the ones whose own support holds the pair are dropped (they own it). Returns how many pairs.
  template <class F>
  std::size_t list_of(std::uint32_t i, bool far, FactorUse use, F& f) const {
    thread_local std::vector<std::uint32_t> js;
    thread_local std::vector<double> r2;  // js's squared distances from i
    thread_local std::vector<float> factors;
    const std::size_t m = tiles_.writable;
    const bool i_writable = i < m;
    const std::uint32_t slot_i = tiles_.slot[i];
    const Vec<D> xi = grid_.sorted_pos[slot_i];
    const double si = 2.0 * h_[i];
    const int reach = reach_of(i);
    const bool check_tiles = reach > tiles_.tile_cells;  // else every partner lies in an adjacent tile
    if (far && !check_tiles) return 0;
    // An unwritable particle pairs only with writable ones (in block steps most have none near).
    const std::vector<std::uint32_t>& prefix = writable_.slot_prefix;
    const bool filtered = !i_writable && !prefix.empty();
    if (filtered && !writable_.any_within(grid_, xi, si)) return 0;
    const std::int32_t* tile_i = tiles_.tile.data() + D * i;
    // Every candidate within i's support but i itself; only writable ones unless i is writable.
    const ScanTarget<D> target{xi, si * si, i, i_writable ? UINT32_MAX : static_cast<std::uint32_t>(m),
                               static_cast<std::uint32_t>(grid_.sorted.size())};
    std::size_t n = 0, earlier = 0;  // found; found in slots before i's
    const auto scan_range = [&](std::uint32_t s0, std::uint32_t s1) {
      if (s0 >= s1 || (filtered && prefix[s1] == prefix[s0])) return;
      if (js.size() < n + (s1 - s0) + kScanSlack) {
        js.resize(2 * (n + (s1 - s0) + kScanSlack));
        r2.resize(js.size());
      }
      n += scan_row<D>(grid_, s0, s1, target, js.data() + n, r2.data() + n);
      if (s1 <= slot_i) earlier = n;  // the ranges come in slot order
    };
    const auto scan = [&](std::uint32_t s0, std::uint32_t s1) {
      if (s0 <= slot_i && slot_i < s1) {
        scan_range(s0, slot_i);
        scan_range(slot_i + 1, s1);
      } else {
        scan_range(s0, s1);
      }
    };
    if (equal_h_) for_each_candidate_range<D>(grid_, xi, si, scan, &slot_i);
    else for_each_candidate_range<D>(grid_, xi, si, scan);
    if (!equal_h_ && earlier > 0) {  // a partner before i owns the pair if its support covers it
      const std::size_t kept = keep_beyond_supports(js.data(), r2.data(), earlier, h_.data());
      std::copy(js.begin() + static_cast<std::ptrdiff_t>(earlier), js.begin() + static_cast<std::ptrdiff_t>(n),
                js.begin() + static_cast<std::ptrdiff_t>(kept));
      std::copy(r2.begin() + static_cast<std::ptrdiff_t>(earlier), r2.begin() + static_cast<std::ptrdiff_t>(n),
                r2.begin() + static_cast<std::ptrdiff_t>(kept));
      n = kept + (n - earlier);
    }
    std::size_t kept = 0;
    const auto keep_if = [&](std::size_t q, bool keep) {  // branch-free, order kept
      js[kept] = js[q];
      r2[kept] = r2[q];
      kept += static_cast<std::size_t>(keep);
    };
    if (check_tiles) {  // keep the pairs of this pass only
      kept = 0;
      for (std::size_t q = 0; q < n; ++q) keep_if(q, tiles_adjacent<D>(tile_i, tiles_.tile.data() + D * js[q]) != far);
      n = kept;
    }
    if (n == 0) return 0;
    if (factors.size() < n) factors.resize(n + n / 4);
    const std::span<const std::uint32_t> list(js.data(), n);
    const std::span<float> list_factors(factors.data(), n);
    if (use == FactorUse::Read) form_(i, list, r2.data(), list_factors);
    f(i, list, list_factors);
    return n;
  }

  const CellGrid<D>& grid_;
  const PairLists& tiles_;
  const std::vector<double>& h_;
  bool equal_h_;
  const CandidateFilter& writable_;
  Form form_;
  double widest_writable_h_ = 0;  // with a filter: the largest h of the writable particles
  mutable std::atomic<std::size_t> found_{0};
  mutable bool counted_ = false;
  std::vector<char> far_tile_, idle_tile_;
  std::vector<char> may_read_;  // per particle, with a filter (summarise_tiles)
  mutable std::vector<char> owns_pairs_;  // per particle, from the first loop
  std::optional<TileJobs> jobs_;  // the busy tiles' schedule
};

}  // namespace sphdisk
