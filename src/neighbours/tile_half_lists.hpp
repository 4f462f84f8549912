#pragma once
// Half lists searched tile by tile on the pair loops' own coloured schedule (pair_lists.hpp), so
// that the first pair loop runs in the search's pass: each list is handed to `visit` as soon as it
// is found, with its partners' squared distances (the search computed them anyway) and room for
// its pair factors, in the order and on the schedule in which for_each_pair_list would call that
// loop. With one smoothing length the density loop (physics/density.hpp) is that loop; it is then
// spared its own pass over the lists and its loads of every partner's position
// (docs/performance.md, "Neighbour search and pair lists"). The lists are
// build_half_neighbour_lists' (neighbour_lists.hpp: the same partners in the same order, so the
// same bits), held per tile (NeighbourLists::tiled);
// their factors are held per tile beside them (TileFactors). No far pairs: tiles span the radius.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string_view>
#include <vector>

#include "core/vec.hpp"
#include "neighbours/cell_grid.hpp"
#include "neighbours/pair_lists.hpp"
#include "parallel/loops.hpp"

namespace sphdisk {

// The pair factors of lists held per tile: tile t's in of_tile[t], numbered like its lists (one
// after the other in tile order). Grown, never shrunk, as the lists' buffers.
struct TileFactors {
  std::vector<std::vector<float>> of_tile;
  std::size_t bytes() const;
};

// visit(i, js, d2, factors): particle i's half list js, d2[q] = |x_i - x_js[q]|^2, factors: room for
// the list's pair factors (to be written by visit). Called for non-empty lists only, concurrently
// only for particles whose pair terms never meet (the coloured schedule of pair_lists.hpp).
using TileListVisit = std::function<void(std::uint32_t i, std::span<const std::uint32_t> js, std::span<const double> d2,
                                         std::span<float> factors)>;

// `out` holds the tile order (build_tile_order with TileWrites::Forward and tiles spanning
// `radius`); its near lists are built and its far lists emptied.
template <int D>
void build_half_lists_on_tiles(const CellGrid<D>& grid, const std::vector<Vec<D>>& pos, double radius, PairLists& out,
                               TileFactors& factors, const TileListVisit& visit);

// The pairs of such lists as the pair loops read them (the interface of StoredPairs, pair_lists.hpp;
// the factors as visit wrote them).
struct TiledPairs {
  const PairLists& lists;
  TileFactors& factors;

  std::size_t writable() const { return lists.writable; }
  void prepare_factors() const {}
  template <class F>
  void for_each_list(F&& f, FactorUse, std::string_view trace_label = {}, FarPairs = FarPairs::Last) const {
    const NeighbourLists& near = lists.near;
    par::for_each_coloured(lists.colour_start, [&](std::size_t c) {
      const std::uint32_t t = lists.tiles_by_colour[c];
      float* at = factors.of_tile[t].data();
      for (std::size_t s = lists.tile_start[t]; s < lists.tile_start[t + 1]; ++s) {
        const std::size_t n = near.count(s);
        if (n == 0) continue;
        f(lists.order[s], near.list(s), std::span<float>(at, n));
        at += n;
      }
    }, trace_label);
  }
};

}  // namespace sphdisk
