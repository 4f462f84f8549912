#include "neighbours/neighbour_lists.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <type_traits>

#include "core/snug_resize.hpp"
#include "neighbours/candidate_filter.hpp"
#include "neighbours/candidate_ranges.hpp"
#include "neighbours/candidate_scan.hpp"
#include "parallel/loops.hpp"

namespace sphdisk {

namespace {

constexpr std::size_t kBlock = NeighbourLists::kBlock;  // lists are made per block, then joined (or not)

struct KeepAll {
  double operator()(std::size_t, std::span<const std::uint32_t>, std::span<const double>, double radius) const { return radius; }
};

// Every candidate other than i itself, in the full stencil around i.
struct AllOthers {
  static constexpr bool kHalf = false;
  std::uint32_t slot_of(std::size_t) const { return 0; }
  std::uint32_t self(std::size_t i) const { return static_cast<std::uint32_t>(i); }
  std::uint32_t limit(std::size_t) const { return UINT32_MAX; }
};

// Half lists (pair_lists.hpp): the candidates after i in cell order (i itself is not among them),
// of pairs with a writable particle.
struct LaterOfWritablePairs {
  static constexpr bool kHalf = true;
  const std::vector<std::uint32_t>& slot;
  std::size_t writable;
  std::uint32_t slot_of(std::size_t i) const { return slot[i]; }
  std::uint32_t self(std::size_t) const { return UINT32_MAX; }
  std::uint32_t limit(std::size_t i) const { return i < writable ? UINT32_MAX : static_cast<std::uint32_t>(writable); }
};

// Lists of particles [first, last) (list k is particle first + k).
// radius_of(i): the search radius of particle i (one value for all, or one per particle).
// settle(i, candidates, radius): the radius to keep (<= radius), or a larger one to search again.
// accept: which candidates are scanned (Accept::kHalf: only those after i in cell order) and which
// may be i's neighbours: every j other than accept.self(i) below accept.limit(i).
// kKeep = false: nothing is listed; only settle sees each particle's candidates (its smoothing-length
// solve), and at most one particle's candidates are held at a time.
// join = false: the lists stay in the blocks (NeighbourLists::joined).
template <bool kKeep = true, int D, class Radius, class Settle, class Accept = AllOthers>
void build_lists(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, std::size_t first, std::size_t last,
                 Radius&& radius_of, Settle&& settle, NeighbourLists& nl, const CandidateFilter& filter = {},
                 const Accept& accept = {}, bool join = true, const std::uint32_t* visit = nullptr) {
  const bool filtered = !filter.slot_prefix.empty();
  const std::uint32_t below = filter.below;  // a local: the stores to the lists below could alias filter.below
  const std::size_t n = last - first;
  const std::size_t nblocks = (n + kBlock - 1) / kBlock;
  auto& block_index = nl.block_index;
  auto& block_count = nl.block_count;
  // Grown, never shrunk: with block timesteps the number of blocks changes from one evaluation to
  // the next, and a block whose buffer were dropped would grow it again, zero-filled, next time.
  if (block_index.size() < nblocks) {
    block_index.resize(nblocks);
    block_count.resize(nblocks);
  }

  // A settle that looks at its candidates gets their squared distances with them.
  constexpr bool kDistances = !std::is_same_v<std::decay_t<Settle>, KeepAll>;
  par::for_each(nblocks, [&](std::size_t b) {
    thread_local std::vector<double> d2;  // of the current particle's candidates
    // Work on local vectors (their headers sit in this thread's cache), reusing the block's memory:
    // pushing through block_index[b] directly would make neighbouring blocks false-share headers.
    std::vector<std::uint32_t> idx, cnt;
    idx.swap(block_index[b]);
    cnt.swap(block_count[b]);
    const std::size_t i0 = first + b * kBlock, i1 = std::min(last, i0 + kBlock);
    cnt.resize(i1 - i0);
    // idx and d2 are buffers whose first `used` entries count: they grow (zero-filled) only when a
    // row of candidates would not fit, so that appending a row costs no fill and no size update.
    std::size_t used = 0;
    const auto room_for = [&](std::size_t more) {
      if (used + more <= idx.size()) return;
      idx.resize(std::max(2 * idx.size(), used + more + 256));
    };
    for (std::size_t list = i0; list < i1; ++list) {
      const std::size_t i = visit ? visit[list] : list;  // list `list` is particle i's
      const Vec<D> xi = pos[i];
      const std::size_t before = used;
      if (filtered && !filter.any_within(grid, xi, radius_of(i))) {  // no candidate in reach: an empty list
        cnt[list - i0] = 0;
        continue;
      }
      for (double radius = radius_of(i);;) {
        const double r2 = radius * radius;
        // The candidates of a row within the radius (candidate_scan.hpp, vectorised in 2D); the index
        // bound `below` is UINT32_MAX outside the filtered search.
        const ScanTarget<D> target{xi, r2, accept.self(i), std::min(accept.limit(i), below),
                                   static_cast<std::uint32_t>(grid.sorted.size())};
        const auto scan = [&](std::uint32_t s0, std::uint32_t s1) {
          if (filtered && filter.slot_prefix[s1] == filter.slot_prefix[s0]) return;
          room_for(s1 - s0 + kScanSlack);
          const std::size_t found = used - before;
          if constexpr (kDistances)
            if (d2.size() < found + (s1 - s0) + kScanSlack) d2.resize(2 * (found + (s1 - s0) + kScanSlack));
          double* out_d2 = kDistances ? d2.data() + found : nullptr;
          used += scan_row<D>(grid, s0, s1, target, idx.data() + used, out_d2);
        };
        if constexpr (Accept::kHalf) {
          const std::uint32_t own = accept.slot_of(i);
          for_each_candidate_range<D>(grid, xi, radius, scan, &own);
        } else {
          for_each_candidate_range<D>(grid, xi, radius, scan);
        }
        const std::size_t found = used - before;
        const double keep = settle(i, std::span<const std::uint32_t>(idx.data() + before, found),
                                   std::span<const double>(d2.data(), kDistances ? found : 0), radius);
        if (keep > radius) {  // search again, wider
          used = before;
          radius = keep;
          continue;
        }
        if (keep < radius) {  // drop candidates beyond the kept radius, in place, order kept (branch-free:
                              // the ~10% dropped lie at random in the list)
          const double keep2 = keep * keep;
          if constexpr (kDistances) {
            used = before + keep_within(idx.data() + before, d2.data(), used - before, keep2);
          } else {
            std::size_t out = before;
            for (std::size_t k = before; k < used; ++k) {
              idx[out] = idx[k];
              out += static_cast<std::size_t>(norm2(pos[idx[k]] - xi) < keep2);
            }
            used = out;
          }
        }
        break;
      }
      if (!kKeep) used = before;
      cnt[list - i0] = static_cast<std::uint32_t>(used - before);
    }
    idx.swap(block_index[b]);  // kept at its buffer size: the block's lists are its first `used` entries
    cnt.swap(block_count[b]);
  }, "neighbour_search", 1);
  if (!kKeep) return;

  nl.offsets_from_blocks(n);
  if (join) nl.join();
}

}  // namespace

template <int D>
void build_neighbour_lists(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, double radius, NeighbourLists& nl,
                           std::size_t count) {
  build_lists(grid, pos, 0, std::min(count, pos.size()), [radius](std::size_t) { return radius; }, KeepAll{}, nl);
}

template <int D>
void build_half_neighbour_lists(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, double radius,
                                const std::vector<std::uint32_t>& slot, std::size_t writable,
                                const std::vector<std::uint32_t>& order, NeighbourLists& nl, bool join) {
  build_lists(grid, pos, 0, pos.size(), [radius](std::size_t) { return radius; }, KeepAll{}, nl, CandidateFilter{},
              LaterOfWritablePairs{slot, writable}, join, order.data());
}

template <int D>
void build_neighbour_lists(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, const std::vector<double>& radius,
                           NeighbourLists& nl, std::size_t count) {
  build_lists(grid, pos, 0, std::min(count, pos.size()), [&radius](std::size_t i) { return radius[i]; }, KeepAll{}, nl);
}

template <int D>
void build_settled_neighbour_lists(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos,
                                   const std::vector<double>& first_radius, const SettleRadius& settle,
                                   NeighbourLists& nl, std::size_t count, bool join, const std::uint32_t* visit) {
  build_lists(grid, pos, 0, std::min(count, pos.size()), [&first_radius](std::size_t i) { return first_radius[i]; },
              settle, nl, CandidateFilter{}, AllOthers{}, join, visit);
}

template <int D>
void settle_without_lists(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, const std::vector<double>& first_radius,
                          const SettleRadius& settle, std::size_t count) {
  NeighbourLists scratch;
  build_lists<false>(grid, pos, 0, std::min(count, pos.size()), [&first_radius](std::size_t i) { return first_radius[i]; }, settle, scratch);
}

void NeighbourLists::offsets_from_blocks(std::size_t n) {
  const std::size_t nblocks = (n + kBlock - 1) / kBlock;
  offsets.resize(n + 1);
  offsets[0] = 0;
  std::vector<std::size_t> block_start(nblocks + 1, 0);
  for (std::size_t b = 0; b < nblocks; ++b) {
    std::size_t used = 0;
    for (const std::uint32_t c : block_count[b]) used += c;
    block_start[b + 1] = block_start[b] + used;
  }
  par::for_each(nblocks, [&](std::size_t b) {
    std::size_t off = block_start[b];
    for (std::size_t k = 0; k < block_count[b].size(); ++k) {
      off += block_count[b][k];
      offsets[b * kBlock + k + 1] = off;
    }
  }, {}, 1);
  joined = false;
  within = nullptr;
  tiled = false;
}

void NeighbourLists::join() {
  if (joined) return;
  const std::size_t n = size();
  renew_snug(index, total());
  par::for_each((n + kBlock - 1) / kBlock, [&](std::size_t b) {
    const std::size_t i0 = b * kBlock, i1 = std::min(n, i0 + kBlock);
    if (within || tiled) {
      for (std::size_t i = i0; i < i1; ++i) std::copy_n(list(i).data(), count(i), index.data() + offsets[i]);
    } else {
      std::copy_n(block_index[b].data(), offsets[i1] - offsets[i0], index.data() + offsets[i0]);
    }
  }, {}, 1);
  held_joined();
}

std::size_t NeighbourLists::bytes() const {
  std::size_t b = offsets.capacity() * sizeof(std::size_t) + index.capacity() * sizeof(std::uint32_t) +
                  start.capacity() * sizeof(const std::uint32_t*);
  for (const auto& v : block_index) b += v.capacity() * sizeof(std::uint32_t);
  for (const auto& v : block_count) b += v.capacity() * sizeof(std::uint32_t);
  return b;
}

template <int D>
void append_neighbour_lists(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, std::size_t first,
                            const std::vector<double>& radius, NeighbourLists& nl, std::size_t candidates_below) {
  nl.join();  // its lists may still be in the block buffers that `more` is built in
  NeighbourLists more;  // the appended lists, built in nl's block buffers (see build_lists)
  more.block_index.swap(nl.block_index);
  more.block_count.swap(nl.block_count);
  CandidateFilter filter;
  filter.build(grid, pos, candidates_below);
  // Left in the blocks, from which each block's lists are copied behind nl's in parallel.
  build_lists(grid, pos, first, pos.size(), [&radius](std::size_t i) { return radius[i]; }, KeepAll{}, more, filter,
              AllOthers{}, false);
  const std::size_t base = nl.total(), listed = nl.size(), added = more.size();
  resize_snug(nl.index, base + more.total());
  nl.offsets.resize(listed + added + 1);
  par::for_each((added + NeighbourLists::kBlock - 1) / NeighbourLists::kBlock, [&](std::size_t b) {
    const std::size_t i0 = b * NeighbourLists::kBlock, i1 = std::min(added, i0 + NeighbourLists::kBlock);
    std::copy_n(more.block_index[b].data(), more.offsets[i1] - more.offsets[i0], nl.index.data() + base + more.offsets[i0]);
    for (std::size_t i = i0; i < i1; ++i) nl.offsets[listed + i + 1] = base + more.offsets[i + 1];
  }, {}, 1);
  nl.block_index.swap(more.block_index);
  nl.block_count.swap(more.block_count);
}

template void build_neighbour_lists(const CellGrid<2>&, const std::vector<Vec<2>>&, double, NeighbourLists&, std::size_t);
template void build_neighbour_lists(const CellGrid<3>&, const std::vector<Vec<3>>&, double, NeighbourLists&, std::size_t);
template void build_neighbour_lists(const CellGrid<2>&, const std::vector<Vec<2>>&, const std::vector<double>&, NeighbourLists&, std::size_t);
template void build_settled_neighbour_lists(const CellGrid<2>&, const std::vector<Vec<2>>&, const std::vector<double>&,
                                            const SettleRadius&, NeighbourLists&, std::size_t, bool, const std::uint32_t*);
template void build_settled_neighbour_lists(const CellGrid<3>&, const std::vector<Vec<3>>&, const std::vector<double>&,
                                            const SettleRadius&, NeighbourLists&, std::size_t, bool, const std::uint32_t*);
template void settle_without_lists(const CellGrid<2>&, const std::vector<Vec<2>>&, const std::vector<double>&,
                                   const SettleRadius&, std::size_t);
template void settle_without_lists(const CellGrid<3>&, const std::vector<Vec<3>>&, const std::vector<double>&,
                                   const SettleRadius&, std::size_t);
template void append_neighbour_lists(const CellGrid<2>&, const std::vector<Vec<2>>&, std::size_t,
                                     const std::vector<double>&, NeighbourLists&, std::size_t);
template void append_neighbour_lists(const CellGrid<3>&, const std::vector<Vec<3>>&, std::size_t,
                                     const std::vector<double>&, NeighbourLists&, std::size_t);
template void build_neighbour_lists(const CellGrid<3>&, const std::vector<Vec<3>>&, const std::vector<double>&, NeighbourLists&, std::size_t);
template void build_half_neighbour_lists(const CellGrid<2>&, const std::vector<Vec<2>>&, double, const std::vector<std::uint32_t>&,
                                         std::size_t, const std::vector<std::uint32_t>&, NeighbourLists&, bool);
template void build_half_neighbour_lists(const CellGrid<3>&, const std::vector<Vec<3>>&, double, const std::vector<std::uint32_t>&,
                                         std::size_t, const std::vector<std::uint32_t>&, NeighbourLists&, bool);

}  // namespace sphdisk

