#include "neighbours/pair_lists.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>

#include "core/snug_resize.hpp"

namespace sphdisk {

namespace {

constexpr std::size_t kBlock = 1024;  // listed particles per work unit of the half-list pass

template <int D>
constexpr int kColours = D == 2 ? 6 : 18;

// The colour of the tile at global tile coordinates g (see pair_lists.hpp).
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

// Whether particles a and b lie in the same or adjacent tiles (tile coordinates, D per particle).
template <int D>
bool adjacent(const std::int32_t* a, const std::int32_t* b) {
  bool yes = true;
  for (std::size_t k = 0; k < D; ++k) yes &= static_cast<std::uint32_t>(b[k] - a[k] + 1) <= 2u;
  return yes;
}

struct Transposed {
  std::uint32_t target, source;  // source comes first in cell order; target has no list of its own
  bool far;
};

}  // namespace

std::size_t PairLists::bytes() const {
  return near.bytes() + far.bytes() + (order.capacity() + slot.capacity()) * sizeof(std::uint32_t) +
         tile.capacity() * sizeof(std::int32_t) +
         tile_start.capacity() * sizeof(std::size_t) + tiles_by_colour.capacity() * sizeof(std::uint32_t) +
         colour_start.capacity() * sizeof(std::size_t);
}

template <int D>
void build_tile_order(const CellGrid<D>& grid, int tile_cells, std::size_t writable, PairLists& out) {
  const std::size_t n = grid.sorted.size();
  out.writable = std::min(writable, n);
  const TileLayout<D> L = tile_layout(grid, std::max(tile_cells, 1));
  const std::size_t ntiles = L.size();

  // Tile order: tile sizes, then each tile's slots copied in parallel.
  out.tile_start.assign(ntiles + 1, 0);
  for (std::size_t t = 0; t < ntiles; ++t) {
    std::size_t count = 0;
    for_each_tile_row(grid, L, t, [&](std::uint32_t s0, std::uint32_t s1) { count += s1 - s0; });
    out.tile_start[t + 1] = out.tile_start[t] + count;
  }
  resize_snug(out.order, n);
  resize_snug(out.slot, n);
  resize_snug(out.tile, D * n);
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

  // Colours: non-empty tiles grouped by colour, in tile order inside a colour.
  out.colour_start.assign(kColours<D> + 1, 0);
  std::vector<int> colour(ntiles);
  for (std::size_t t = 0; t < ntiles; ++t) {
    std::array<int, D> gt;
    for (std::size_t k = 0; k < D; ++k) gt[k] = L.first[k] + L.coord[t][k];
    colour[t] = colour_of<D>(gt);
    if (out.tile_start[t + 1] > out.tile_start[t]) ++out.colour_start[static_cast<std::size_t>(colour[t]) + 1];
  }
  for (int c = 0; c < kColours<D>; ++c) out.colour_start[static_cast<std::size_t>(c) + 1] += out.colour_start[static_cast<std::size_t>(c)];
  out.tiles_by_colour.resize(out.colour_start.back());
  {
    std::vector<std::size_t> fill(out.colour_start.begin(), out.colour_start.end() - 1);
    for (std::size_t t = 0; t < ntiles; ++t)
      if (out.tile_start[t + 1] > out.tile_start[t]) out.tiles_by_colour[fill[static_cast<std::size_t>(colour[t])]++] = static_cast<std::uint32_t>(t);
  }

}

template <int D>
void build_half_lists(const NeighbourLists& full, PairLists& out) {
  const std::size_t n = out.order.size();
  const std::size_t m = out.writable;
  if (full.size() != m) throw std::logic_error("build_half_lists: the full lists must be those of the writable particles");
  const std::vector<std::uint32_t>& slot = out.slot;
  const std::int32_t* tile = out.tile.data();
  // Half lists of the listed particles: the entries that come later in cell order, in list order.
  // A pair whose first particle has no list is handed to it (transposed).
  const std::size_t nblocks = (m + kBlock - 1) / kBlock;
  struct Block {
    std::vector<std::uint32_t> near, far, near_count, far_count;
    std::vector<Transposed> transposed;
  };
  std::vector<Block> blocks(nblocks);
  par::for_each(nblocks, [&](std::size_t b) {
    Block B;  // filled locally (vector headers in this thread's cache), then moved in
    const std::size_t i0 = b * kBlock, i1 = std::min(m, i0 + kBlock);
    B.near_count.resize(i1 - i0);
    B.far_count.resize(i1 - i0);
    for (std::size_t i = i0; i < i1; ++i) {
      const std::uint32_t slot_i = slot[i];
      const std::size_t near0 = B.near.size(), far0 = B.far.size();
      // Branch-free append of the near pairs (about half the entries, at random); far and
      // transposed pairs are rare.
      std::size_t end = near0;
      B.near.resize(near0 + full.count(i));
      for (const std::uint32_t* it = full.begin(i); it != full.end(i); ++it) {
        const std::uint32_t j = *it;
        const bool later = slot[j] > slot_i, near = adjacent<D>(tile + D * i, tile + D * j);
        B.near[end] = j;
        end += static_cast<std::size_t>(later & near);
        if (!near && later) B.far.push_back(j);
        if (!later && j >= m) B.transposed.push_back({j, static_cast<std::uint32_t>(i), !near});
      }
      B.near.resize(end);
      B.near_count[i - i0] = static_cast<std::uint32_t>(end - near0);
      B.far_count[i - i0] = static_cast<std::uint32_t>(B.far.size() - far0);
    }
    blocks[b] = std::move(B);
  }, "neighbour_search", 1);

  // Transposed pairs grouped by target (counting sort in block order), each group in cell order.
  std::vector<std::size_t> tstart(n - m + 1, 0);
  for (const Block& B : blocks)
    for (const Transposed& p : B.transposed) ++tstart[p.target - m + 1];
  for (std::size_t k = 0; k < n - m; ++k) tstart[k + 1] += tstart[k];
  std::vector<Transposed> tsorted(tstart[n - m]);
  {
    std::vector<std::size_t> fill(tstart.begin(), tstart.end() - 1);
    for (const Block& B : blocks)
      for (const Transposed& p : B.transposed) tsorted[fill[p.target - m]++] = p;
  }
  par::for_each(n - m, [&](std::size_t k) {
    std::sort(tsorted.begin() + static_cast<std::ptrdiff_t>(tstart[k]), tsorted.begin() + static_cast<std::ptrdiff_t>(tstart[k + 1]),
              [&](const Transposed& a, const Transposed& b) { return slot[a.source] < slot[b.source]; });
  });

  // Join: offsets of both lists, then the entries, in parallel.
  for (NeighbourLists* nl : {&out.near, &out.far}) {
    nl->offsets.resize(n + 1);
    nl->offsets[0] = 0;
  }
  for (std::size_t b = 0; b < nblocks; ++b)
    for (std::size_t k = 0; k < blocks[b].near_count.size(); ++k) {
      const std::size_t i = b * kBlock + k;
      out.near.offsets[i + 1] = out.near.offsets[i] + blocks[b].near_count[k];
      out.far.offsets[i + 1] = out.far.offsets[i] + blocks[b].far_count[k];
    }
  for (std::size_t i = m; i < n; ++i) {
    std::size_t nf = 0;
    for (std::size_t k = tstart[i - m]; k < tstart[i - m + 1]; ++k) nf += tsorted[k].far;
    out.near.offsets[i + 1] = out.near.offsets[i] + (tstart[i - m + 1] - tstart[i - m]) - nf;
    out.far.offsets[i + 1] = out.far.offsets[i] + nf;
  }
  resize_snug(out.near.index, out.near.offsets[n]);
  resize_snug(out.far.index, out.far.offsets[n]);
  par::for_each(nblocks, [&](std::size_t b) {
    const std::size_t i0 = b * kBlock;
    std::copy(blocks[b].near.begin(), blocks[b].near.end(), out.near.index.begin() + static_cast<std::ptrdiff_t>(out.near.offsets[i0]));
    std::copy(blocks[b].far.begin(), blocks[b].far.end(), out.far.index.begin() + static_cast<std::ptrdiff_t>(out.far.offsets[i0]));
  }, {}, 1);
  par::for_each(n - m, [&](std::size_t k) {
    std::size_t a = out.near.offsets[m + k], f = out.far.offsets[m + k];
    for (std::size_t e = tstart[k]; e < tstart[k + 1]; ++e)
      (tsorted[e].far ? out.far.index[f++] : out.near.index[a++]) = tsorted[e].source;
  });
}

template <int D>
void build_pair_lists(const NeighbourLists& full, const CellGrid<D>& grid, int tile_cells, PairLists& out) {
  build_tile_order(grid, tile_cells, full.size(), out);
  build_half_lists<D>(full, out);
}

void no_far_pairs(PairLists& out) {
  out.far.offsets.assign(out.near.offsets.size(), 0);
  out.far.index.clear();
}

template void build_tile_order(const CellGrid<2>&, int, std::size_t, PairLists&);
template void build_tile_order(const CellGrid<3>&, int, std::size_t, PairLists&);
template void build_half_lists<2>(const NeighbourLists&, PairLists&);
template void build_half_lists<3>(const NeighbourLists&, PairLists&);
template void build_pair_lists(const NeighbourLists&, const CellGrid<2>&, int, PairLists&);
template void build_pair_lists(const NeighbourLists&, const CellGrid<3>&, int, PairLists&);

}  // namespace sphdisk
