// The adaptive smoothing lengths' stage of a rate evaluation: each particle's h solved while its
// neighbours are searched (physics/smoothing_length.hpp), over ranks with a halo that is widened
// where a solve reached beyond it, then the half lists of the interacting pairs (stored lists) or
// the tile order (pairs searched anew).
#include <cmath>
#include <limits>

#include "evaluate/cells_and_tiles.hpp"
#include "evaluate/rate_evaluator.hpp"
#include "neighbours/cell_grid.hpp"
#include "neighbours/pair_lists.hpp"
#include "physics/smoothing_length.hpp"

namespace sphdisk {

using namespace evaluation;

// Solves h_i while searching each particle's neighbours (widening the search where the solution
// lies beyond it), then the half lists of the pairs r < 2 max(h_i, h_j) (pair_lists.hpp).
//
// With particles spread over processes, the ghosts must hold every particle within the search
// radius of an owned particle (need) and every particle whose own support 2 h_j reaches one
// (reach). Both are known only after the solve, so the halo is chosen from the previous h with a
// margin and checked afterwards; where it fell short (rare: h grew by more than the margin), the
// solve is repeated with a wider halo from the same start values, so the result is the one a
// single process gets.
//
// Only the first `active` particles solve for h; the others (inactive ones of a block timestep)
// keep theirs and take part like ghosts: their gather lists, restricted to active neighbours, give
// the pairs that only their own support covers.
template <int D>
bool RateEvaluator<D>::adaptive_lists(Particles<D>& p, std::size_t active) {
  return with_kernel(kernel_, [&](auto k) { return adaptive_lists_with(k, p, active); });
}

template <int D>
template <class K>
bool RateEvaluator<D>::adaptive_lists_with(K, Particles<D>& p, std::size_t active) {
  const std::size_t owned = p.size();
  // A super-step's stage (stage_) keeps h and rho: no solve, the cells of the evaluation before.
  if (!stage_) {
    // Each solve starts from h extrapolated from the particle's last solutions (smoothing_length.hpp).
    par::for_each(active, [&p](std::size_t i) {
      const double h = p.h[i];
      p.h[i] = predicted_smoothing_length(h, p.h_prev[i], p.h_prev2[i]);
      remember_smoothing_length(h, p.h_prev[i], p.h_prev2[i]);
    });
    smoothing_length_solves_ += active;
  }
  // One process, every particle active (the common case): the gather lists are made in the pair
  // loops' tile order, and the half lists are left inside them, where the loops read them
  // (pair_lists.hpp). Else list i is particle i's, as appending (inactive particles) needs.
  const bool tile_ordered = !domain_ && active == owned && storage_ == PairStorage::Stored && !whole_.set;
  double cell_size;
  // The median h sets the cell size (kCellOverMedianH): the denser particles scan few cells and the
  // rest (larger h) reach over more cells; any cell size gives the same lists.
  if (stage_) {  // a super-step's stage: the choices of the evaluation before it
    cell_size = kept_.cell_size;
    widest_support_ = kept_.widest_support;
  } else if (domain_) {
    const std::uint64_t total = domain_->sum(owned);
    cell_size = kCellOverMedianH<D> * domain_->kth_smallest(p.h, total / 2);
    widest_support_ = 2.0 * domain_->kth_smallest(p.h, static_cast<std::uint64_t>(kTileQuantile * static_cast<double>(total)));
  } else if (whole_.set) {  // the involved particles of a partial evaluation: the whole set's lattice
    cell_size = whole_.lattice.cell_size;
    widest_support_ = whole_.widest_support;
  } else {
    const CellsAndTiles c = cells_and_tiles<D>(p.h);
    cell_size = c.cell_size;
    widest_support_ = c.widest_support;
  }
  if (domain_) {
    need_.resize(owned);
    reach_.resize(owned);
    // (Inactive particles pair with no ghost: they draw none, add_ghosts.)
    for (std::size_t i = 0; i < owned; ++i) {
      need_[i] = i < active ? 2.0 * kSkin * p.h[i] * kHaloMargin : -1.0;
      reach_[i] = 2.0 * p.h[i] * kHaloMargin;
    }
    h_start_ = p.h;
  }
  // The particles' common mass (0 if they differ) selects the density sum's form: over ranks of
  // all their particles, so that every rank takes the same form (one whose own and ghost particles
  // are alike could otherwise take the other, with other round-off).
  double uniform_mass_all = 0;
  if (domain_) {
    const double lo = domain_->min(par::reduce(owned, std::numeric_limits<double>::infinity(), [&](std::size_t i) { return p.mass[i]; },
                                               [](double a, double b) { return std::min(a, b); }));
    const double hi = domain_->max(par::reduce(owned, -std::numeric_limits<double>::infinity(), [&](std::size_t i) { return p.mass[i]; },
                                               [](double a, double b) { return std::max(a, b); }));
    uniform_mass_all = lo == hi && lo > 0 ? lo : 0.0;
  } else if (!whole_.set) {
    uniform_mass_all = uniform_mass_of(p);
  }
  // (A partial evaluation on the involved particles takes the whole set's choices: the same ones.)
  const bool grid_kept = stage_ && kept_.grid_of_all;
  if (!stage_) kept_ = {true, cell_size, widest_support_, !domain_ && !whole_.set};
  for (;;) {
    Lattice<D> lattice;
    if (domain_) {
      {
        ScopedPhase t(timers_, "communication");
        lattice = domain_->add_ghosts(p, cell_size, [&](std::size_t i) { return need_[i]; },
                                      [&](std::size_t i) { return reach_[i]; });
      }
      ScopedPhase t(timers_, "cell_build");
      build_cell_grid(lattice, p.pos, p.id, grid_);
    } else if (whole_.set) {
      ScopedPhase t(timers_, "cell_build");
      lattice = whole_.lattice;
      build_cell_grid(lattice, p.pos, p.id, grid_);
    } else {
      ScopedPhase t(timers_, "cell_build");
      // (A stage's particles have not moved: the same cells, the particles only renumbered.)
      if (grid_kept) renumber_particles(grid_, moved_);
      else build_cell_grid(p.pos, p.id, cell_size, grid_);
      lattice = Lattice<D>{grid_.lo, grid_.cell_size, grid_.dims};  // one process: the grid is the lattice
    }
    double extent = 0;  // a search beyond twice the lattice's diagonal cannot find more particles
    for (int k = 0; k < D; ++k) extent += std::pow(lattice.cell_size * lattice.dims[static_cast<std::size_t>(k)], 2);
    const double widest = 4.0 * std::sqrt(extent);
    search_radius_.resize(active);
    for (std::size_t i = 0; i < active; ++i) search_radius_[i] = 2.0 * kSkin * p.h[i];
    halo_short_.assign(domain_ ? owned : 0, 0.0);
    const double uniform_mass = whole_.set ? whole_.uniform_mass : uniform_mass_all;
    solve_sums_.assign(active, 0);
    const SettleRadius settle = [&](std::size_t i, std::span<const std::uint32_t> cand, std::span<const double> dist2,
                                    double searched) {
      if (stage_) return std::min(searched, 2.0 * p.h[i]);  // h kept: only its gather list
      const SmoothingLengthResult r = smoothing_length_at<K, D>(i, p, cand, dist2, p.h[i], eta_, 0.5 * searched, uniform_mass);
      solve_sums_[i] += static_cast<std::uint32_t>(r.sums);  // (a wider search solves i again)
      if (r.beyond_candidates && searched < widest) {
        p.h[i] = r.h;  // the start value of the wider search
        const double wider = 2.0 * kSkin * r.h;
        if (domain_ && wider > need_[i]) {  // beyond the ghosts: stop here, search again with more
          halo_short_[i] = wider;
          return searched;
        }
        if (whole_.set && wider > whole_.complete_radius[i]) {  // beyond the involved particles: the same
          search_short_.store(true, std::memory_order_relaxed);
          return searched;
        }
        return wider;
      }
      p.h[i] = r.beyond_candidates ? 0.5 * searched : r.h;  // too few particles in the whole domain: keep all
      store(p.rho[i], r.rho);  // at p.h[i] (beyond: at h_max = searched / 2)
      return std::min(searched, 2.0 * p.h[i]);
    };
    {
      ScopedPhase t(timers_, "neighbour_search");
      if (tile_ordered) build_tile_order(grid_, tile_cells(), active, pairs_lists_, TileWrites::AllNeighbours);
      if (storage_ == PairStorage::Rescan) {
        if (!stage_) settle_without_lists(grid_, p.pos, search_radius_, settle, active);  // (a stage: nothing to settle)
      }
      // Left in the search's blocks (the half lists are made there; appending joins them).
      else build_settled_neighbour_lists(grid_, p.pos, search_radius_, settle, candidates_, active, false,
                                         tile_ordered ? pairs_lists_.order.data() : nullptr);
    }
    smoothing_length_sums_ += total_of(solve_sums_);
    if (lean() && !domain_) release_memory(search_radius_, solve_sums_);
    if (!domain_) break;
    bool again = false;
    for (std::size_t i = 0; i < owned; ++i) {
      if (halo_short_[i] > 0) {
        need_[i] = halo_short_[i] * kHaloMargin;
        again = true;  // p.h[i] keeps the start value of the wider search
      } else if (2.0 * p.h[i] > reach_[i]) {
        reach_[i] = 2.0 * p.h[i] * kHaloMargin;
        again = true;
      }
    }
    if (!domain_->any(again)) break;
    ++halo_widenings_;
    domain_->remove_ghosts(p);
    for (std::size_t i = 0; i < owned; ++i)
      if (halo_short_[i] == 0) p.h[i] = h_start_[i];
  }
  if (search_short_.load(std::memory_order_relaxed)) return false;
  if (domain_) refresh_ghosts(p, GhostStage::SmoothingLength);
  ScopedPhase t(timers_, "neighbour_search");
  if (storage_ == PairStorage::Rescan) {
    scan_order(p.pos, active);
    return true;
  }
  if (active < p.size()) {
    // Ghosts' (and inactive particles') gather lists with their own h: the pairs that only their own
    // support covers come from them (pair_lists.hpp). Only pairs with an active particle matter.
    search_radius_.resize(p.size());
    for (std::size_t i = active; i < p.size(); ++i) search_radius_[i] = 2.0 * p.h[i];
    append_neighbour_lists(grid_, p.pos, active, search_radius_, candidates_, active < owned ? active : SIZE_MAX);
  }
  // Each pair once, from the gather lists (pair_lists.hpp).
  if (!tile_ordered) build_tile_order(grid_, tile_cells(), active, pairs_lists_, TileWrites::AllNeighbours);
  build_half_lists_from_gather(candidates_, p.pos, p.h, pairs_lists_, tile_ordered);
  ++list_builds_;
  return true;
}

template bool RateEvaluator<2>::adaptive_lists(Particles<2>&, std::size_t);
template bool RateEvaluator<3>::adaptive_lists(Particles<3>&, std::size_t);

}  // namespace sphdisk
