#include "neighbours/tile_half_lists.hpp"

#include <algorithm>

#include "neighbours/candidate_ranges.hpp"
#include "neighbours/candidate_scan.hpp"

namespace sphdisk {

std::size_t TileFactors::bytes() const {
  std::size_t b = 0;
  for (const auto& v : of_tile) b += v.capacity() * sizeof(float);
  return b;
}

template <int D>
void build_half_lists_on_tiles(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, double radius, PairLists& out,
                               TileFactors& factors, const TileListVisit& visit) {
  NeighbourLists& nl = out.near;
  const std::size_t n = out.order.size(), ntiles = out.tile_start.size() - 1;
  // Buffers grown, never shrunk (as build_lists keeps its blocks': no zero-filled regrowth).
  if (nl.block_index.size() < ntiles) nl.block_index.resize(ntiles);
  if (factors.of_tile.size() < ntiles) factors.of_tile.resize(ntiles);
  nl.offsets.resize(n + 1);  // each list's count at offsets[s + 1] first, summed after
  nl.offsets[0] = 0;
  const double r2 = radius * radius;
  const std::size_t writable = out.writable;
  par::for_each_coloured(out.colour_start, [&](std::size_t c) {
    const std::uint32_t t = out.tiles_by_colour[c];
    thread_local std::vector<double> d2;  // of the current particle's candidates
    // Local vectors (their headers in this thread's cache), on the tile's memory.
    std::vector<std::uint32_t> idx;
    std::vector<float> F;
    idx.swap(nl.block_index[t]);
    F.swap(factors.of_tile[t]);
    std::size_t used = 0;
    for (std::size_t s = out.tile_start[t]; s < out.tile_start[t + 1]; ++s) {
      const std::uint32_t i = out.order[s];
      const Vec<D> xi = pos[i];
      // The candidates after i in cell order (i itself is not among them) of pairs with a writable
      // particle (build_half_neighbour_lists' LaterOfWritablePairs).
      const ScanTarget<D> target{xi, r2, UINT32_MAX, i < writable ? UINT32_MAX : static_cast<std::uint32_t>(writable),
                                 static_cast<std::uint32_t>(grid.sorted.size())};
      const std::size_t before = used;
      const auto scan = [&](std::uint32_t s0, std::uint32_t s1) {
        const std::size_t room = s1 - s0 + kScanSlack, found = used - before;
        if (used + room > idx.size()) idx.resize(std::max(2 * idx.size(), used + room + 256));
        if (found + room > d2.size()) d2.resize(2 * (found + room));
        used += scan_row<D>(grid, s0, s1, target, idx.data() + used, d2.data() + found);
      };
      const std::uint32_t own = out.slot[i];
      for_each_candidate_range<D>(grid, xi, radius, scan, &own);
      const std::size_t count = used - before;
      nl.offsets[s + 1] = count;
      if (count == 0) continue;
      if (used > F.size()) F.resize(std::max(2 * F.size(), used + 256));
      visit(i, std::span<const std::uint32_t>(idx.data() + before, count), std::span<const double>(d2.data(), count),
            std::span<float>(F.data() + before, count));
    }
    idx.swap(nl.block_index[t]);
    F.swap(factors.of_tile[t]);
  }, "neighbour_search");
  for (std::size_t s = 0; s < n; ++s) nl.offsets[s + 1] += nl.offsets[s];
  nl.start.resize(n);
  par::for_each(ntiles, [&](std::size_t t) {
    const std::size_t first = out.tile_start[t];
    for (std::size_t s = first; s < out.tile_start[t + 1]; ++s)
      nl.start[s] = nl.block_index[t].data() + (nl.offsets[s] - nl.offsets[first]);
  }, {}, 1);
  nl.held_in_tiles();
  no_far_pairs(out);
}

template void build_half_lists_on_tiles(const CellGrid<2>&, const std::vector<Vec<2>>&, double, PairLists&, TileFactors&,
                                        const TileListVisit&);
template void build_half_lists_on_tiles(const CellGrid<3>&, const std::vector<Vec<3>>&, double, PairLists&, TileFactors&,
                                        const TileListVisit&);

}  // namespace sphdisk
