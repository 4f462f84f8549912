#pragma once
// Half lists: every interacting pair once, so that each pair term is evaluated once and added to
// both particles (P98 sec. 4.1 visited every pair from both sides and lost up to 2x, Fig. 4), and
// the schedule that does this on threads with the same bits for any thread or rank count.
//
// With one search radius (build_half_neighbour_lists) a pair belongs to the particle that comes
// first in cell order (the grid's order: cells of the shared lattice x fastest, by x and ID inside a
// cell), so its partners lie in its own row of cells or the rows above: the half stencil of the
// symmetric sequential code. Tiles are blocks of T^D cells; a tile's task evaluates the pairs of its
// particles (in cell order) and, for near pairs (tiles equal or adjacent), writes only to its own
// tile, its row neighbours x-1 and x+1 and the three tiles of the next row (in 3D also the 9 tiles
// of the next layer). Tiles coloured (tx mod 3, ty mod 2) in 2D and (tx mod 3, ty mod 3, tz mod 2)
// in 3D never write to a common tile within a colour, so a colour's tiles run in parallel without
// locks or atomics, and every particle receives its pair terms in a fixed order: colour by colour
// (the tiles that write to it all have different colours), inside a tile in cell order. Half lists
// made from gather lists (variable h) may give a pair to its second particle; their tiles write to
// every adjacent tile (TileWrites::AllNeighbours) and run, uncoloured, as jobs that keep tile order
// among the tiles that write to a common particle (tile_jobs.hpp). Far pairs (tiles not adjacent:
// a particle whose support is much wider than a tile) follow all tiles, in tile order (or precede
// them: FarPairs::First). Nothing in the order
// depends on threads or on how particles are split over ranks (a rank's cells keep the lattice's
// relative order).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "core/pair_source.hpp"  // FactorUse, FarPairs
#include "core/snug_resize.hpp"
#include "core/vec.hpp"
#include "neighbours/cell_grid.hpp"
#include "neighbours/neighbour_lists.hpp"
#include "neighbours/tile_jobs.hpp"
#include "parallel/loops.hpp"

namespace sphdisk {

// Which tiles a tile's pairs write to: itself and the tiles after it (x-1, x+1 and the next row;
// half lists searched with one radius, a pair owned by its first particle), or every adjacent tile
// (half lists from gather lists, and pairs searched anew by the pair loops, pair_scan.hpp: the
// owner may come second). Only the first is coloured (6 colours in 2D, 18 in 3D); the second runs
// as ordered jobs (tile_jobs.hpp), which keep the order of a particle's terms without a barrier
// between colours.
enum class TileWrites { Forward, AllNeighbours };

struct PairLists {
  // Half lists of every particle of the grid, stored in tile order: list s is particle order[s]'s,
  // so that the pair loops, which visit the particles in that order, read the lists (and the pair
  // factors, numbered like them) front to back instead of hopping through memory
  // (docs/performance.md, "Neighbour search and pair lists").
  NeighbourLists near, far;
  std::vector<std::uint32_t> order;       // particles in tile order
  std::vector<std::size_t> tile_start;    // tile t holds order[tile_start[t] .. tile_start[t + 1])
  // TileWrites::Forward only (empty otherwise): tile indices colour by colour, colour c being
  // tiles_by_colour[colour_start[c] .. colour_start[c + 1]).
  std::vector<std::uint32_t> tiles_by_colour;
  std::vector<std::size_t> colour_start;
  std::size_t writable = 0;               // pair terms are wanted for particles [0, writable) only
  std::vector<std::uint32_t> slot;        // each particle's place in cell order (its grid slot)
  std::vector<std::int32_t> tile;         // each particle's tile coordinates (D per particle)
  std::array<int, 3> tile_count{1, 1, 1};  // tiles per dimension (tile t = x + count_x (y + count_y z))
  int tile_cells = 1;                     // cells per tile and dimension
  double tile_length = 0;                 // tile_cells x the grid's cell size
  TileWrites writes = TileWrites::Forward;  // which tiles a tile's pairs may write to (the schedule)

  std::size_t total() const { return near.total() + far.total(); }  // pairs; also the pair-factor count
  std::size_t bytes() const;
};

// Step 1: the tile order of the grid's particles (order, tiles, slots; colours for Forward) with tiles of
// tile_cells^D cells; pair terms are wanted for the particles [0, writable).
template <int D>
void build_tile_order(const CellGrid<D>& grid, int tile_cells, std::size_t writable, PairLists& out,
                      TileWrites writes = TileWrites::Forward);

// Step 2, from gather lists with variable smoothing lengths: `gather` holds every particle's list of
// the j with |x_i - x_j| < 2 h_i (ghosts' and inactive particles' restricted to writable partners,
// or not). Pairs interact when |x_i - x_j| < 2 max(h_i, h_j) (interaction through i's own support
// or through j's; the pair-averaged kernel gradient keeps every pair term antisymmetric,
// Hernquist & Katz 1989). A pair belongs to the first particle in cell order whose gather list
// holds it, which may be the second particle of the pair: `out`'s tile order must have been built
// with TileWrites::AllNeighbours.
// in_tile_order: gather list s is particle out.order[s]'s (searched in that order); else list i is
// particle i's. Either way the half lists are left inside the gather lists, where the pair loops
// read them (out.near.within = &gather): the gather lists are overwritten in part and must stay
// until the pairs have been read.
template <int D>
void build_half_lists_from_gather(NeighbourLists& gather, const std::vector<Vec<D>>& pos,
                                  const std::vector<double>& h, PairLists& out, bool in_tile_order = false);

// Step 2, searched directly into out.near (build_half_neighbour_lists of neighbour_lists.hpp) with
// tiles spanning the search radius, so that no pair is far: empties the far lists.
void no_far_pairs(PairLists& out);

// Whether particles a and b lie in the same or adjacent tiles (tile coordinates, D per particle).
template <int D>
bool tiles_adjacent(const std::int32_t* a, const std::int32_t* b) {
  bool yes = true;
  for (std::size_t k = 0; k < D; ++k) yes &= static_cast<std::uint32_t>(b[k] - a[k] + 1) <= 2u;
  return yes;
}

// Calls f(i, js, k0) once per particle i with a non-empty half list: js its partners, numbered
// k0, k0 + 1, ... (near pairs first, as per-pair arrays such as the pair factors are indexed: in
// the order of the calls within each part).
// Concurrent calls never share a particle, and each particle's terms come in the fixed order
// described above. A list at a time lets the physics keep i's sums in registers.
template <class F>
void for_each_pair_list(const PairLists& pl, F&& f, std::string_view trace_label = {}, FarPairs far_pairs = FarPairs::Last) {
  const auto far_lists = [&] {
    const NeighbourLists& far = pl.far;
    const std::size_t base = pl.near.total();
    if (far.total() == 0) return;
    // Serial (far pairs may share particles). The offsets are cumulative, so a run of lists without
    // far pairs is skipped at once: few lists have any, and a test of every list would be a serial
    // pass over all particles in each pair loop.
    constexpr std::size_t kRun = 1024;
    const std::size_t n = pl.order.size();
    for (std::size_t s0 = 0; s0 < n; s0 += kRun) {
      const std::size_t s1 = std::min(n, s0 + kRun);
      if (far.offsets[s1] == far.offsets[s0]) continue;
      for (std::size_t s = s0; s < s1; ++s)
        if (far.count(s) > 0) f(pl.order[s], std::span<const std::uint32_t>(far.begin(s), far.count(s)), base + far.offsets[s]);
    }
  };
  if (far_pairs == FarPairs::First) far_lists();
  const NeighbourLists& near = pl.near;
  const auto tile_lists = [&](std::uint32_t t) {
    const std::size_t s0 = pl.tile_start[t], s1 = pl.tile_start[t + 1];
    for (std::size_t s = s0; s < s1; ++s) {
      // Lists left inside gather lists (NeighbourLists::within) in particle order lie apart in
      // memory: the next one is fetched while this one is read.
      if (near.within && s + 4 < s1) {
        const std::span<const std::uint32_t> next = near.list(s + 4);
        for (std::size_t k = 0; k < next.size(); k += 16) __builtin_prefetch(next.data() + k);
      }
      if (near.count(s) > 0) f(pl.order[s], near.list(s), near.offsets[s]);  // joined, in the builder's blocks or within the gather lists
    }
  };
  if (pl.writes == TileWrites::AllNeighbours) {
    const TileJobs jobs(pl.tile_count, [&](std::size_t t) { return pl.tile_start[t + 1] > pl.tile_start[t]; });
    jobs.run_one_pass(tile_lists, trace_label);
  } else {
    par::for_each_coloured(pl.colour_start, [&](std::size_t c) { tile_lists(pl.tiles_by_colour[c]); }, trace_label);
  }
  if (far_pairs == FarPairs::Last) far_lists();
}

// Calls f(i, j, k) once for every pair (i first in cell order, k its number), in the same order.
template <class F>
void for_each_pair(const PairLists& pl, F&& f, std::string_view trace_label = {}) {
  for_each_pair_list(pl, [&f](std::uint32_t i, std::span<const std::uint32_t> js, std::size_t k0) {
    for (std::size_t q = 0; q < js.size(); ++q) f(i, js[q], k0 + q);
  }, trace_label);
}

// The pairs as the pair loops of physics/ read them (the other form is ScannedPairs of
// pair_scan.hpp): the stored half lists with one stored factor per pair.
// for_each_list(f, use) calls f(i, js, F) with F[q] the factor of pair (i, js[q]), to be written
// (FactorUse::Write) or read; prepare_factors() sizes the factors before they are written.
struct StoredPairs {
  const PairLists& lists;
  OverwriteVector<float>& factors;  // physics/pair_factors.hpp

  std::size_t writable() const { return lists.writable; }
  void prepare_factors() const { renew_snug(factors, lists.total()); }
  template <class F>
  void for_each_list(F&& f, FactorUse, std::string_view trace_label = {}, FarPairs far_pairs = FarPairs::Last) const {
    float* all = factors.data();
    for_each_pair_list(lists, [&](std::uint32_t i, std::span<const std::uint32_t> js, std::size_t k0) {
      f(i, js, std::span<float>(all + k0, js.size()));
    }, trace_label, far_pairs);
  }
};

// Stored half lists whose factors the first loop that reads them forms on its way (each list's
// factors just before the loop's terms of that list, while its partners are in cache), so that no
// pass over the pairs is spent on the factors alone. form(i, js, factors) writes the factors of
// the pairs (i, js[q]). The factors are sized on construction.
template <class Form>
struct StoredPairsFormingFactors {
  StoredPairs stored;
  Form form;
  mutable bool formed = false;

  StoredPairsFormingFactors(const PairLists& lists, OverwriteVector<float>& factors, Form form_)
      : stored{lists, factors}, form(form_) {
    stored.prepare_factors();
  }
  std::size_t writable() const { return stored.writable(); }
  void prepare_factors() const {}
  template <class F>
  void for_each_list(F&& f, FactorUse use, std::string_view trace_label = {}, FarPairs far_pairs = FarPairs::Last) const {
    if (formed || use == FactorUse::Write) {
      formed = true;
      stored.for_each_list(f, use, trace_label, far_pairs);
      return;
    }
    stored.for_each_list([&](std::uint32_t i, std::span<const std::uint32_t> js, std::span<float> factors) {
      form(i, js, factors);
      f(i, js, factors);
    }, use, trace_label, far_pairs);
    formed = true;
  }
};

}  // namespace sphdisk
