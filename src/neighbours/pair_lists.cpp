#include "neighbours/pair_lists.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <memory>
#include <stdexcept>

#include "core/snug_resize.hpp"
#include "neighbours/candidate_scan.hpp"

namespace sphdisk {

namespace {

constexpr std::size_t kBlock = 1024;  // lists per work unit of half_lists_inside

template <int D>
constexpr int kColours = D == 2 ? 6 : 18;

// The colour of the tile at global tile coordinates g for TileWrites::Forward (see pair_lists.hpp):
// tiles of one colour lie three apart along x (and y in 3D), where they write to the tiles on both
// sides, and two apart along the last axis, where they write only forward.
template <int D>
int colour_of(const std::array<int, D>& g) {
  if constexpr (D == 2) return g[0] % 3 + 3 * (g[1] % 2);
  else return g[0] % 3 + 3 * (g[1] % 3) + 9 * (g[2] % 2);
}

template <int D>
struct TileLayout {
  int T = 1;
  std::array<int, D> first{}, count{};   // global tile index of local tile 0; local tiles per dimension
  std::vector<std::array<int, D>> coord;  // local tile coordinates of each tile

  std::size_t size() const { return coord.size(); }
};

template <int D>
TileLayout<D> tile_layout(const CellGrid<D>& g, int T) {
  TileLayout<D> L;
  L.T = T;
  std::size_t n = 1;
  for (std::size_t k = 0; k < D; ++k) {
    L.first[k] = g.origin[k] / T;
    L.count[k] = (g.origin[k] + g.dims[k] - 1) / T - L.first[k] + 1;
    n *= static_cast<std::size_t>(L.count[k]);
  }
  L.coord.resize(n);
  for (std::size_t t = 0; t < n; ++t) {
    std::size_t rest = t;
    for (std::size_t k = 0; k < D; ++k) {
      L.coord[t][k] = static_cast<int>(rest % static_cast<std::size_t>(L.count[k]));
      rest /= static_cast<std::size_t>(L.count[k]);
    }
  }
  return L;
}

// Calls row(s0, s1) for the grid slots of tile t, row of cells by row of cells (cell order).
template <int D, class Row>
void for_each_tile_row(const CellGrid<D>& g, const TileLayout<D>& L, std::size_t t, Row&& row) {
  std::array<int, D> lo, hi;  // local cell range [lo, hi) of the tile
  for (std::size_t k = 0; k < D; ++k) {
    const int gt = L.first[k] + L.coord[t][k];
    lo[k] = std::max(gt * L.T, g.origin[k]) - g.origin[k];
    hi[k] = std::min((gt + 1) * L.T, g.origin[k] + g.dims[k]) - g.origin[k];
  }
  auto emit = [&](std::array<int, D> c) {
    c[0] = lo[0];
    const std::size_t a = g.linear(c);
    c[0] = hi[0] - 1;
    row(g.offsets[a], g.offsets[g.linear(c) + 1]);
  };
  std::array<int, D> c = lo;
  if constexpr (D == 2) {
    for (c[1] = lo[1]; c[1] < hi[1]; ++c[1]) emit(c);
  } else {
    for (c[2] = lo[2]; c[2] < hi[2]; ++c[2])
      for (c[1] = lo[1]; c[1] < hi[1]; ++c[1]) emit(c);
  }
}

}  // namespace

std::size_t PairLists::bytes() const {
  return near.bytes() + far.bytes() + (order.capacity() + slot.capacity()) * sizeof(std::uint32_t) +
         tile.capacity() * sizeof(std::int32_t) +
         tile_start.capacity() * sizeof(std::size_t) + tiles_by_colour.capacity() * sizeof(std::uint32_t) +
         colour_start.capacity() * sizeof(std::size_t);
}

template <int D>
void build_tile_order(const CellGrid<D>& grid, int tile_cells, std::size_t writable, PairLists& out, TileWrites writes) {
  const std::size_t n = grid.sorted.size();
  out.writable = std::min(writable, n);
  const TileLayout<D> L = tile_layout(grid, std::max(tile_cells, 1));
  out.tile_cells = L.T;
  out.tile_count = {1, 1, 1};
  for (std::size_t k = 0; k < D; ++k) out.tile_count[k] = L.count[k];
  out.tile_length = L.T * grid.cell_size;
  out.writes = writes;
  const std::size_t ntiles = L.size();

  // Tile order: tile sizes, then each tile's slots copied in parallel.
  out.tile_start.assign(ntiles + 1, 0);
  for (std::size_t t = 0; t < ntiles; ++t) {
    std::size_t count = 0;
    for_each_tile_row(grid, L, t, [&](std::uint32_t s0, std::uint32_t s1) { count += s1 - s0; });
    out.tile_start[t + 1] = out.tile_start[t] + count;
  }
  renew_snug(out.order, n);
  renew_snug(out.slot, n);
  renew_snug(out.tile, D * n);
  par::for_each(ntiles, [&](std::size_t t) {
    std::size_t s = out.tile_start[t];
    for_each_tile_row(grid, L, t, [&](std::uint32_t s0, std::uint32_t s1) {
      for (std::uint32_t slot = s0; slot < s1; ++slot, ++s) {
        const std::uint32_t i = grid.sorted[slot];
        out.order[s] = i;
        out.slot[i] = slot;
        for (std::size_t k = 0; k < D; ++k) out.tile[D * i + k] = L.coord[t][k];
      }
    });
  }, "neighbour_search", 1);

  // Colours (Forward only; tiles that write to all their neighbours run as ordered jobs,
  // tile_jobs.hpp): non-empty tiles grouped by colour, in tile order inside a colour.
  out.tiles_by_colour.clear();
  out.colour_start.clear();
  if (writes != TileWrites::Forward) return;
  const int ncolours = kColours<D>;
  out.colour_start.assign(static_cast<std::size_t>(ncolours) + 1, 0);
  std::vector<int> colour(ntiles);
  for (std::size_t t = 0; t < ntiles; ++t) {
    std::array<int, D> gt;
    for (std::size_t k = 0; k < D; ++k) gt[k] = L.first[k] + L.coord[t][k];
    colour[t] = colour_of<D>(gt);
    if (out.tile_start[t + 1] > out.tile_start[t]) ++out.colour_start[static_cast<std::size_t>(colour[t]) + 1];
  }
  for (int c = 0; c < ncolours; ++c) out.colour_start[static_cast<std::size_t>(c) + 1] += out.colour_start[static_cast<std::size_t>(c)];
  out.tiles_by_colour.resize(out.colour_start.back());
  {
    std::vector<std::size_t> fill(out.colour_start.begin(), out.colour_start.end() - 1);
    for (std::size_t t = 0; t < ntiles; ++t)
      if (out.tile_start[t + 1] > out.tile_start[t]) out.tiles_by_colour[fill[static_cast<std::size_t>(colour[t])]++] = static_cast<std::uint32_t>(t);
  }
  // Largest tiles first inside each colour, so that the dynamic schedule ends evenly (the order
  // inside a colour changes no result: its tiles write to disjoint particles).
  for (int c = 0; c < ncolours; ++c) {
    auto first = out.tiles_by_colour.begin() + static_cast<std::ptrdiff_t>(out.colour_start[static_cast<std::size_t>(c)]);
    auto last = out.tiles_by_colour.begin() + static_cast<std::ptrdiff_t>(out.colour_start[static_cast<std::size_t>(c) + 1]);
    std::stable_sort(first, last, [&](std::uint32_t a, std::uint32_t b) {
      return out.tile_start[a + 1] - out.tile_start[a] > out.tile_start[b + 1] - out.tile_start[b];
    });
  }
}

// The half lists of the pairs in the gather lists `src` (lists of every particle of the grid, each
// in cell order as the neighbour search gives them, entry j of i's list within 2 h_i): an entry j of
// i's list that comes later in cell order stays in i's half list; an earlier one stays too where j's
// own list lacks i (|x_i - x_j| >= 2 h_j, earlier_partners in candidate_scan.hpp: the pair is seen
// by i's support only, ~14% of the pairs on the 100k ring), else it is dropped (j lists i and keeps
// the pair). So each pair belongs to the first particle whose list holds it, and every half list is
// a filtered copy of its gather list, in the same order, built block by block in parallel. As an
// owner may come second in cell order, its pairs write to tiles on both sides: the schedule must
// be TileWrites::AllNeighbours. Pairs of two unwritable particles are dropped.
// within_tile(i): whether i's whole list lies within one tile length of it, so that every partner
// is in the same or an adjacent tile (cells differ by at most tile_cells, tiles by at most one) and
// the tiles need not be compared (all but the ~1% widest supports).
// HalfListOf: lacking() writes the earlier partners of i whose own lists lack i to a buffer; where
// whole_tail(i), i's half list is those followed by its later partners; else sorted() makes it from
// them (far pairs and dropped pairs taken out); left_inside() leaves the result in i's gather list.
template <int D, class WithinTile>
struct HalfListOf {
  const PairLists& out;
  const std::vector<Vec<D>>& pos;
  const std::vector<double>& h;
  WithinTile& within_tile;

  EarlierPartners lacking(std::uint32_t i, std::span<const std::uint32_t> own, std::uint32_t* near) const {
    const std::vector<std::uint32_t>& slot = out.slot;
    assert(std::is_sorted(own.begin(), own.end(), [&](std::uint32_t a, std::uint32_t c) { return slot[a] < slot[c]; }));
    // Pairs of two unwritable particles are dropped: an unwritable i keeps only writable lacking ones.
    const auto limit = i < out.writable ? UINT32_MAX : static_cast<std::uint32_t>(out.writable);
    if constexpr (D == 2)
      return earlier_partners(own.data(), own.size(), slot[i], slot.data(), pos[i], pos.data(), h.data(), limit, near);
    else
      return earlier_partners_scalar<D>(own.data(), own.size(), slot[i], slot.data(), pos[i], pos.data(), h.data(), limit, near);
  }

  bool whole_tail(std::uint32_t i) const { return i < out.writable && within_tile(i); }

  // near[0, end): the lacking earlier partners, then the later ones. Sorted into near and far
  // (branch-free for the near ones), and pairs of two unwritable particles dropped (the lacking
  // ones are writable already: lacking's limit).
  std::size_t sorted(std::uint32_t i, std::size_t end, std::uint32_t* near, std::vector<std::uint32_t>& far) const {
    const std::size_t m = out.writable;
    const std::int32_t* tile = out.tile.data();
    const bool i_writable = i < m;
    std::size_t kept = 0;
    for (std::size_t k = 0; k < end; ++k) {
      const std::uint32_t j = near[k];
      const bool is_near = tiles_adjacent<D>(tile + D * i, tile + D * j);
      const bool wanted = i_writable | (j < m);
      near[kept] = j;
      kept += static_cast<std::size_t>(is_near & wanted);
      if (!is_near && wanted) far.push_back(j);
    }
    return kept;
  }

  // i's half list left inside its gather list `own` (NeighbourLists::within): where whole_tail(i)
  // the later partners stay where the search wrote them and the lacking earlier ones (few) are
  // written just before them, over earlier partners already read; else the list (far pairs and
  // dropped ones taken out, the widest ~1%) is written to the end of `own` whole. buffer: room for
  // own.size() + kScanSlack entries. Returns where the half list starts in `own` (it runs to the end).
  std::size_t left_inside(std::uint32_t i, std::span<std::uint32_t> own, std::uint32_t* buffer,
                          std::vector<std::uint32_t>& far) const {
    const EarlierPartners e = lacking(i, own, buffer);
    if (whole_tail(i)) {
      std::copy_n(buffer, e.lacking, own.data() + (e.count - e.lacking));
      return e.count - e.lacking;
    }
    std::copy(own.begin() + static_cast<std::ptrdiff_t>(e.count), own.end(), buffer + e.lacking);
    const std::size_t kept = sorted(i, e.lacking + own.size() - e.count, buffer, far);
    std::copy_n(buffer, kept, own.data() + (own.size() - kept));
    return own.size() - kept;
  }
};

// The per-list work of both builders below: list k of src is particle i's; its half list is left
// inside it (start: its first entry), its far pairs appended to far. Returns the near count.
template <class Half>
std::size_t half_list_inside(const Half& half, NeighbourLists& src, std::size_t k, std::uint32_t i,
                             const std::uint32_t*& start, std::vector<std::uint32_t>& far) {
  thread_local std::vector<std::uint32_t> scratch;  // in cache; it only grows
  const std::span<std::uint32_t> own = src.entries(k);
  const std::size_t first = half.left_inside(i, own, scratch_for(scratch, own.size() + kScanSlack), far);
  start = own.data() + first;
  return own.size() - first;
}

// Every half list is left inside its gather list (NeighbourLists::within), where the pair loops
// read it: no half list is copied or held apart from the gather lists (that would be a second copy
// of every pair, at the peak memory of a build). The gather lists are read as they lie in memory,
// list k being particle order[k]'s where they were searched in tile order (in_tile_order), else
// particle k's; the near lists are numbered in tile order (near list s lies in gather list s, or
// in order[s]), and the far lists (few) are joined in tile order.
template <int D, class WithinTile>
void half_lists_inside(NeighbourLists& src, const std::vector<Vec<D>>& pos, const std::vector<double>& h, PairLists& out,
                       WithinTile&& within_tile, bool in_tile_order) {
  const HalfListOf<D, WithinTile> half{out, pos, h, within_tile};
  const std::size_t n = src.size();
  const std::size_t nblocks = (n + kBlock - 1) / kBlock;
  NeighbourLists& near = out.near;
  // Entries and block buffers of an earlier build are released, not held beside the gather lists.
  for (NeighbourLists* nl : {&out.near, &out.far}) {
    std::vector<std::vector<std::uint32_t>>().swap(nl->block_index);
    std::vector<std::vector<std::uint32_t>>().swap(nl->block_count);
  }
  OverwriteVector<std::uint32_t>().swap(near.index);
  near.start.resize(n);
  OverwriteVector<const std::uint32_t*> particle_start(in_tile_order ? 0 : n);
  const std::uint32_t** start = in_tile_order ? near.start.data() : particle_start.data();  // by gather list
  OverwriteVector<std::uint32_t> count(n);  // by gather list
  struct Block {
    std::vector<std::uint32_t> far, far_count;
  };
  std::vector<Block> blocks(nblocks);
  par::for_each(nblocks, [&](std::size_t b) {
    Block B;  // filled locally (vector headers in this thread's cache), then moved in
    const std::size_t k0 = b * kBlock, k1 = std::min(n, k0 + kBlock);
    B.far_count.resize(k1 - k0);
    for (std::size_t k = k0; k < k1; ++k) {
      const std::size_t far_before = B.far.size();
      const auto i = static_cast<std::uint32_t>(in_tile_order ? out.order[k] : k);
      count[k] = static_cast<std::uint32_t>(half_list_inside(half, src, k, i, start[k], B.far));
      B.far_count[k - k0] = static_cast<std::uint32_t>(B.far.size() - far_before);
    }
    blocks[b] = std::move(B);
  }, "neighbour_search", 1);

  // In tile order: the near lists' offsets and starts, and the far lists joined (where each far
  // list starts in its block, the offsets, then every list copied in parallel).
  const auto list_of = [&](std::size_t s) -> std::size_t { return in_tile_order ? s : out.order[s]; };
  par::prefix_offsets(n, [&](std::size_t s) { return std::size_t{count[list_of(s)]}; }, near.offsets, "neighbour_search");
  if (!in_tile_order)
    par::for_each(n, [&](std::size_t s) { near.start[s] = particle_start[out.order[s]]; }, "neighbour_search", 4096);
  near.view_inside(src);
  OverwriteVector<std::uint32_t> far_at(n);  // by gather list
  par::for_each(nblocks, [&](std::size_t b) {
    std::uint32_t far_end = 0;
    for (std::size_t k = 0; k < blocks[b].far_count.size(); ++k) {
      far_at[b * kBlock + k] = far_end;
      far_end += blocks[b].far_count[k];
    }
  }, "neighbour_search", 1);
  out.far.held_joined();
  par::prefix_offsets(n, [&](std::size_t s) {
    const std::size_t k = list_of(s);
    return std::size_t{blocks[k / kBlock].far_count[k % kBlock]};
  }, out.far.offsets, "neighbour_search");
  resize_snug(out.far.index, out.far.offsets[n]);
  par::for_each(n, [&](std::size_t s) {
    const std::size_t k = list_of(s);
    std::copy_n(blocks[k / kBlock].far.data() + far_at[k], out.far.count(s), out.far.index.data() + out.far.offsets[s]);
  }, "neighbour_search", 1024);
}

template <int D>
void build_half_lists_from_gather(NeighbourLists& gather, const std::vector<Vec<D>>& pos,
                                  const std::vector<double>& h, PairLists& out, bool in_tile_order) {
  if (gather.size() != out.order.size())
    throw std::logic_error("build_half_lists_from_gather: every particle of the grid needs its gather list");
  if (out.writes != TileWrites::AllNeighbours)
    throw std::logic_error("build_half_lists_from_gather: the tile order needs TileWrites::AllNeighbours (a pair may belong to its second particle)");
  // j's gather list lacks i exactly when i lies outside j's own support (the test of its search).
  // i's list reaches 2 h_i; the margin covers the round-off of the cell coordinates.
  const double within = (1.0 - 1e-9) * out.tile_length;
  const auto within_tile = [&](std::size_t i) { return 2.0 * h[i] < within; };
  half_lists_inside<D>(gather, pos, h, out, within_tile, in_tile_order);
}


void no_far_pairs(PairLists& out) {
  out.far.offsets.assign(out.near.offsets.size(), 0);
  out.far.index.clear();
}

template void build_tile_order(const CellGrid<2>&, int, std::size_t, PairLists&, TileWrites);
template void build_tile_order(const CellGrid<3>&, int, std::size_t, PairLists&, TileWrites);
template void build_half_lists_from_gather(NeighbourLists&, const std::vector<Vec<2>>&, const std::vector<double>&, PairLists&, bool);
template void build_half_lists_from_gather(NeighbourLists&, const std::vector<Vec<3>>&, const std::vector<double>&, PairLists&, bool);


}  // namespace sphdisk
