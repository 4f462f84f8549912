#include "app/rate_evaluator.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/error.hpp"
#include "core/named_choice.hpp"
#include "core/snug_resize.hpp"
#include "neighbours/cell_grid.hpp"
#include "neighbours/involved_particles.hpp"
#include "neighbours/pair_lists.hpp"
#include "neighbours/pair_scan.hpp"
#include "parallel/nth_values.hpp"
#include "physics/density.hpp"
#include "physics/forces.hpp"
#include "physics/list_factors.hpp"
#include "physics/smoothing_length.hpp"
#include "physics/viscous_rates.hpp"
#include "physics/viscous_stress.hpp"

namespace sphdisk {

namespace {

// Candidates are searched to kSkin x 2 h_i, so h may grow by kSkin while it is solved for before
// the particle's search must be repeated.
constexpr double kSkin = 1.05;

// Halos (ghosts of other ranks, or the involved particles of a partial evaluation) reach this much
// beyond the first search radius, so that h may grow by it before the solve must be repeated.
constexpr double kHaloMargin = 1.25;

// Partial evaluations with at most this fraction of the particles active work on the involved
// particles (evaluate_involved), unless these are more than kInvolvedMost of all. Either way the
// bits are the same. With few active particles this halves an evaluation; with more, the involved
// particles are a large part of all, and copying them, searching them and the occasional repeat
// cost more than the work over all particles they spare (docs/performance.md, "Block timesteps").
constexpr double kInvolvedActive = 0.02;
constexpr double kInvolvedMost = 0.5;

// Tiles of the pair schedule (pair_lists.hpp) span at least 16 x 16 cells in 2D (8^3 in 3D), ~1,000
// particles: tiles that run side by side lie apart, so what a tile reads of its neighbours is
// reused only inside the tile, and larger tiles reuse more of it (docs/performance.md,
// "Neighbour search and pair lists"). The tiles also span the supports of all but the widest 1%
// of particles, whose pairs reaching beyond the next tile are evaluated after the others. The tile
// size depends on the particles only, never on the thread count (it sets the order of the sums).
template <int D>
constexpr int kMinTileCells = D == 2 ? 16 : 8;
constexpr double kTileQuantile = 0.99;

// The k-th smallest (from 0) of v for k = fraction * size, for each of the fractions (< 1).
template <std::size_t N>
std::array<double, N> quantiles(const std::vector<double>& v, const std::array<double, N>& fractions) {
  std::array<std::size_t, N> ranks{};
  for (std::size_t f = 0; f < N; ++f) ranks[f] = static_cast<std::size_t>(fractions[f] * static_cast<double>(v.size()));
  return par::nth_values(v, ranks);
}

// One process, adaptive h: the cell size (from the median h: the denser particles scan few cells
// and the rest reach over more; any cell size gives the same lists) and the support the tiles span
// (all but the widest 1%), from every particle's h.
struct CellsAndTiles {
  double cell_size, widest_support;
};
CellsAndTiles cells_and_tiles(const std::vector<double>& h) {
  const auto [median, wide] = quantiles<2>(h, {0.5, kTileQuantile});
  return {kSkin * median, 2.0 * wide};
}

std::size_t total_of(const std::vector<std::uint32_t>& counts) {
  return par::sum<std::size_t>(counts.size(), [&](std::size_t i) { return static_cast<std::size_t>(counts[i]); });
}

}  // namespace

Smoothing smoothing_from_name(std::string_view name) {
  static constexpr NamedChoice<Smoothing> kNames[] = {{"adaptive", Smoothing::Adaptive}, {"constant", Smoothing::Constant}};
  return choice_from_name<Smoothing>("sph.smoothing", name, kNames);
}

PairStorage pair_storage_from_name(std::string_view name) {
  static constexpr NamedChoice<PairStorage> kNames[] = {{"rescan", PairStorage::Rescan}, {"stored", PairStorage::Stored}};
  return choice_from_name<PairStorage>("sph.pair_lists", name, kNames);
}

template <int D>
RateEvaluator<D>::RateEvaluator(KernelType kernel, double h, PhysicsParams phys, PhaseTimers& timers,
                                Smoothing smoothing, double neighbours)
    : kernel_(kernel), h_(h), phys_(phys), timers_(timers), smoothing_(smoothing),
      eta_(eta_for_neighbours<D>(neighbours)) {}

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
template <class K>
bool RateEvaluator<D>::adaptive_lists(Particles<D>& p, std::size_t active) {
  const std::size_t owned = p.size();
  // Each solve starts from h extrapolated from the particle's last solutions (smoothing_length.hpp).
  par::for_each(active, [&p](std::size_t i) {
    const double h = p.h[i];
    p.h[i] = predicted_smoothing_length(h, p.h_prev[i], p.h_prev2[i]);
    remember_smoothing_length(h, p.h_prev[i], p.h_prev2[i]);
  });
  smoothing_length_solves_ += active;
  // One process, every particle active (the common case): the gather lists are made in the pair
  // loops' tile order, and the half lists are left inside them, where the loops read them
  // (pair_lists.hpp). Else list i is particle i's, as appending (inactive particles) needs.
  const bool tile_ordered = !domain_ && active == owned && storage_ == PairStorage::Stored && !whole_.set;
  double cell_size;
  // The median h sets the cell size: the denser particles scan few cells and the rest (larger h)
  // reach over more cells; any cell size gives the same lists.
  if (domain_) {
    const std::uint64_t total = domain_->sum(owned);
    cell_size = kSkin * domain_->kth_smallest(p.h, total / 2);
    widest_support_ = 2.0 * domain_->kth_smallest(p.h, static_cast<std::uint64_t>(kTileQuantile * static_cast<double>(total)));
    need_.resize(owned);
    reach_.resize(owned);
    for (std::size_t i = 0; i < owned; ++i) {
      need_[i] = 2.0 * kSkin * p.h[i] * kHaloMargin;
      reach_[i] = 2.0 * p.h[i] * kHaloMargin;
    }
    h_start_ = p.h;
  } else if (whole_.set) {  // the involved particles of a partial evaluation: the whole set's lattice
    cell_size = whole_.lattice.cell_size;
    widest_support_ = whole_.widest_support;
  } else {
    const CellsAndTiles c = cells_and_tiles(p.h);
    cell_size = c.cell_size;
    widest_support_ = c.widest_support;
  }
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
      build_cell_grid(p.pos, p.id, cell_size, grid_);
      lattice = Lattice<D>{grid_.lo, grid_.cell_size, grid_.dims};  // one process: the grid is the lattice
    }
    double extent = 0;  // a search beyond twice the lattice's diagonal cannot find more particles
    for (int k = 0; k < D; ++k) extent += std::pow(lattice.cell_size * lattice.dims[static_cast<std::size_t>(k)], 2);
    const double widest = 4.0 * std::sqrt(extent);
    search_radius_.resize(active);
    for (std::size_t i = 0; i < active; ++i) search_radius_[i] = 2.0 * kSkin * p.h[i];
    halo_short_.assign(domain_ ? owned : 0, 0.0);
    const double uniform_mass = whole_.set ? whole_.uniform_mass : uniform_mass_of(p);  // ghosts included
    solve_sums_.assign(active, 0);
    const SettleRadius settle = [&](std::size_t i, std::span<const std::uint32_t> cand, std::span<const double> dist2,
                                    double searched) {
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
      if (storage_ == PairStorage::Rescan) settle_without_lists(grid_, p.pos, search_radius_, settle, active);
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

template <int D>
void RateEvaluator<D>::release_rebuilt_memory() {
  release_memory(grid_, candidates_, search_radius_, slopes_, pairs_lists_,
                 writable_filter_, factors_, gradient_sums_, heating_scratch_, force_scratch_.inv_rho,
                 force_scratch_.p_over_rho2, force_scratch_.log_rho, force_scratch_.rho_without_self, force_scratch_.scales,
                 solve_sums_, involved_, members_, predicted_h_);
}

template <int D>
void RateEvaluator<D>::evaluate(Particles<D>& p, std::size_t active) {
  active = std::min(active, p.size());
  if (evaluate_involved(p, active)) return;
  evaluate_particles(p, active);
}

// The choices evaluate_particles makes from all particles (cell size and lattice, the tiles' span,
// the common mass) are made here first, and the evaluation on the involved particles takes them
// (whole_): every cell lies where it lies in the whole set's grid, so candidates, lists and tiles
// come in the same order and every sum takes the same terms in the same order. The involved set
// holds every particle within complete_radius[i] of each active particle i (involved_particles.hpp):
// with adaptive h that covers its first search (2 kSkin h from its predicted h) with kHaloMargin
// to spare; a solve that wants a wider search sets search_short_, and the evaluation is repeated
// with twice the radii (as a rank's solve is repeated with more ghosts).
template <int D>
void RateEvaluator<D>::evaluate_again(Particles<D>& p, std::size_t active) {
  active = std::min(active, p.size());
  if (smoothing_ != Smoothing::Adaptive) {
    evaluate(p, active);
    return;
  }
  history_.resize(2 * active);
  par::for_each(active, [&](std::size_t i) {
    history_[2 * i] = p.h_prev[i];
    history_[2 * i + 1] = p.h_prev2[i];
    p.h_prev[i] = p.h_prev2[i] = p.h[i];  // predicted_smoothing_length then starts from h
  });
  evaluate(p, active);
  par::for_each(active, [&](std::size_t i) {
    p.h_prev[i] = history_[2 * i];
    p.h_prev2[i] = history_[2 * i + 1];
  });
}

template <int D>
bool RateEvaluator<D>::evaluate_involved(Particles<D>& p, std::size_t active) {
  const std::size_t n = p.size();
  if (!involved_enabled_ || domain_ || storage_ != PairStorage::Stored || active == 0 ||
      static_cast<double>(active) > kInvolvedActive * static_cast<double>(n))
    return false;
  double cell_size;
  std::vector<double>& radius = whole_.complete_radius;
  radius.resize(active);
  {
    ScopedPhase t(timers_, "neighbour_search");
    if (smoothing_ == Smoothing::Adaptive) {
      predicted_h_ = p.h;  // as adaptive_lists predicts them, before it takes the quantiles
      par::for_each(active, [&](std::size_t i) { predicted_h_[i] = predicted_smoothing_length(p.h[i], p.h_prev[i], p.h_prev2[i]); });
      const CellsAndTiles c = cells_and_tiles(predicted_h_);
      cell_size = c.cell_size;
      whole_.widest_support = c.widest_support;
      par::for_each(active, [&](std::size_t i) { radius[i] = kHaloMargin * 2.0 * kSkin * predicted_h_[i]; });
    } else {
      const double support = 2.0 * h_;  // no pair reaches further
      std::fill(radius.begin(), radius.end(), support);
      cell_size = 0.5 * support;
      whole_.widest_support = support;
    }
    Vec<D> lo, hi;
    bounding_box(p.pos, lo, hi);
    whole_.lattice = make_lattice(lo, hi, n, cell_size);
    whole_.uniform_mass = uniform_mass_of(p);
  }
  for (;;) {
    {
      ScopedPhase t(timers_, "neighbour_search");
      involved_particles(p.pos, p.h, active, radius, members_);
      if (static_cast<double>(members_.size()) > kInvolvedMost * static_cast<double>(n)) return false;
      // (Not the integrator's state inside its step: no evaluation reads it; nor the fields the run
      // does not use.)
      const unsigned absent = p.absent_fields() | kStepState;
      if (involved_.absent_fields() != absent) involved_.set_absent_fields(absent);
      involved_.resize(members_.size());
      involved_.for_each_field_with(p, [&](const FieldInfo&, auto& to, const auto& from) {
        par::for_each(members_.size(), [&](std::size_t k) { to[k] = from[members_[k]]; });
      });
    }
    whole_.set = true;
    const bool done = evaluate_particles(involved_, active);
    whole_.set = false;
    if (done) break;
    ++involved_widenings_;
    for (double& r : radius) r *= 2.0;
  }
  ScopedPhase t(timers_, "neighbour_search");
  // The active particles are the first ones in both: their new values go back.
  p.for_each_field_with(involved_, [&](const FieldInfo&, auto& to, const auto& from) {
    par::for_each(active, [&](std::size_t i) { to[i] = from[i]; });
  });
  ++involved_evaluations_;
  return true;
}

template <int D>
bool RateEvaluator<D>::evaluate_particles(Particles<D>& p, std::size_t active) {
  // Set by a search beyond the involved particles (whole_.set only); cleared here, not where the
  // involved evaluation starts, so that one given up on (too many involved particles) leaves no
  // stale flag for the evaluation over all particles that follows.
  search_short_ = false;
  const bool rescan = storage_ == PairStorage::Rescan;
  std::size_t pair_count = 0;
  bool complete = true;
  with_kernel(kernel_, [&](auto k) {
    using K = decltype(k);
    if (smoothing_ == Smoothing::Adaptive) {
      if (!adaptive_lists<K>(p, active)) {
        complete = false;
        return;
      }
      if (rescan) {
        // No per-particle kernels kept either: each is made from h where needed (the same values).
        const auto form = [&p](std::uint32_t i, std::span<const std::uint32_t> js, const double* r2, std::span<float> F) {
          factors_from_h<K, D>(p.h[i], p.h.data(), js, r2, F);
        };
        const ScannedPairs<D, decltype(form)> scanned(grid_, pairs_lists_, p.h, false, writable_filter_, form);
        pair_loops(p, scanned, [&](const auto& pairs) { set_volumes(p, pairs.writable()); });
        pair_count = scanned.pairs_found();
        return;
      }
      {
        ScopedPhase t(timers_, "density");
        bind_kernel_slopes<K>(p, slopes_);
      }
      // rho came with h; the pair factors are formed by the velocity-gradient loop on its way, a
      // list at a time (physics/list_factors.hpp).
      const auto form = [this, &p](std::uint32_t i, std::span<const std::uint32_t> js, std::span<float> factors) {
        form_list_factors<K>(p.pos.data(), slopes_.data(), i, js, factors);
      };
      const StoredPairsFormingFactors<decltype(form)> pairs(pairs_lists_, factors_, form);
      pair_loops(p, pairs, [&](const auto&) { set_volumes(p, pairs.writable()); });
      pair_count = pairs_lists_.total();
      return;
    }
    const double support = 2.0 * h_;  // all kernels have compact support 2h
    widest_support_ = support;
    if (domain_) {
      Lattice<D> lattice;
      {
        ScopedPhase t(timers_, "communication");
        const auto radius = [support](std::size_t) { return support; };
        lattice = domain_->add_ghosts(p, 0.5 * support, radius, radius);
      }
      std::fill(p.h.begin(), p.h.end(), h_);  // what the timestep criteria and the snapshots read
      ScopedPhase t(timers_, "cell_build");
      build_cell_grid(lattice, p.pos, p.id, grid_);
    } else {
      std::fill(p.h.begin(), p.h.end(), h_);
      ScopedPhase t(timers_, "cell_build");
      if (whole_.set) build_cell_grid(whole_.lattice, p.pos, p.id, grid_);  // involved particles: the whole set's lattice
      else build_cell_grid(p.pos, p.id, 0.5 * support, grid_);
    }
    const KernelAt<K, D> kern(h_);
    // Lists searched anew, with nothing between the search and the density loop: the search runs on
    // the pair loops' schedule and sums the density on its way (tile_half_lists.hpp; the same bits).
    const bool summed_in_search = !rescan && density_in_search_;
    {
      ScopedPhase t(timers_, summed_in_search ? "search_and_density" : "neighbour_search");
      if (rescan) {
        scan_order(p.pos, active);
      } else if (summed_in_search) {
        build_tile_order(grid_, tile_cells(), active, pairs_lists_);
        ConstantHDensity<K, D> sums(p, kern, pairs_lists_.writable);
        build_half_lists_on_tiles(grid_, p.pos, support, pairs_lists_, tile_factors_, density_while_searching(sums));
        sums.finish();
        ++list_builds_;
      } else {
        // Each pair once, searched directly: tiles span the support, so no pair is far.
        build_tile_order(grid_, tile_cells(), active, pairs_lists_);
        // Read where the search left them (its blocks).
        build_half_neighbour_lists(grid_, p.pos, support, pairs_lists_.slot, active, pairs_lists_.order, pairs_lists_.near,
                                   false);
        no_far_pairs(pairs_lists_);
        ++list_builds_;
      }
    }
    const auto density = [&](const auto& pairs) { compute_density(p, pairs, kern); };
    if (summed_in_search) {
      pair_loops(p, TiledPairs{pairs_lists_, tile_factors_}, [](const auto&) {});  // (the density came with the lists)
      pair_count = pairs_lists_.total();
    } else if (rescan) {
      const auto form = [kern](std::uint32_t, std::span<const std::uint32_t> js, const double* r2, std::span<float> F) {
        for (std::size_t q = 0; q < js.size(); ++q) F[q] = static_cast<float>(kern.dW_over_r(std::sqrt(r2[q])));
      };
      const ScannedPairs<D, decltype(form)> scanned(grid_, pairs_lists_, p.h, true, writable_filter_, form);
      pair_loops(p, scanned, density);
      pair_count = scanned.pairs_found();
    } else {
      pair_loops(p, StoredPairs{pairs_lists_, factors_}, density);
      pair_count = pairs_lists_.total();
    }
  });
  if (!complete) return false;
  ++evaluations_;
  if (domain_) domain_->remove_ghosts(p);
  pairs_ += pair_count;
  updates_ += active;
  return true;
}

template <int D>
template <class Pairs, class Density>
void RateEvaluator<D>::pair_loops(Particles<D>& p, const Pairs& pairs, Density&& density) {
  {
    ScopedPhase t(timers_, "density");
    density(pairs);
  }
  refresh_ghosts(p, GhostStage::Density);
  // The force correction's heating loop runs between the gradient and force loops, where the
  // particles hold an energy rate (an energy equation: core/particles.hpp).
  const bool corrected_heating = phys_.force_correction && !p.du_dt.empty();
  // Pairs searched anew are searched once for the gradient and force loops together, unless ghosts'
  // stresses must be fetched between the two or the corrected heating's loop lies between.
  if constexpr (JoinsLoops<Pairs>) {
    if (!domain_ && !corrected_heating) {
      ScopedPhase t(timers_, "gradient_and_forces");
      compute_stress_and_accelerations(p, pairs, phys_, gradient_sums_, force_scratch_, gravity_);
      if (lean()) release_memory(gradient_sums_);
      return;
    }
  }
  {
    ScopedPhase t(timers_, "velocity_gradient");
    compute_viscous_stress(p, pairs, phys_, gradient_sums_, force_scratch_.scales);
    if (lean()) release_memory(gradient_sums_);
  }
  refresh_ghosts(p, GhostStage::Stress);
  if (corrected_heating) {
    ScopedPhase t(timers_, "velocity_gradient");
    add_force_corrected_heating(p, pairs, heating_scratch_);
  }
  ScopedPhase t(timers_, "forces");
  compute_accelerations(p, pairs, phys_, force_scratch_, gravity_);
}

template <int D>
void RateEvaluator<D>::scan_order(const std::vector<Vec<D>>& pos, std::size_t writable) {
  build_tile_order(grid_, tile_cells(), writable, pairs_lists_, TileWrites::AllNeighbours);
  writable_filter_.build(grid_, pos, writable);
}

// Tiles of the pair schedule span the supports of all but the widest particles.
template <int D>
int RateEvaluator<D>::tile_cells() const {
  return std::max(kMinTileCells<D>, static_cast<int>(std::ceil(widest_support_ / grid_.cell_size)));
}


template <int D>
std::vector<std::pair<std::string, std::size_t>> RateEvaluator<D>::memory() const {
  std::size_t scratch = 0;
  for (const auto* v : {&search_radius_, &need_, &reach_, &h_start_, &halo_short_, &history_}) scratch += v->capacity() * sizeof(double);
  scratch += gradient_sums_.capacity() * sizeof(GradientSums<D>) + heating_scratch_.capacity() * sizeof(Mat<D>) +
             (force_scratch_.inv_rho.capacity() + force_scratch_.p_over_rho2.capacity() + force_scratch_.log_rho.capacity() +
              force_scratch_.rho_without_self.capacity() + 2 * force_scratch_.scales.capacity()) *
                 sizeof(double);
  scratch += writable_filter_.bytes();
  scratch += predicted_h_.capacity() * sizeof(double);
  return {{"half_lists", pairs_lists_.bytes()},
          {"involved_particles", involved_.bytes() + members_.capacity() * sizeof(std::uint32_t)},
          {"candidate_lists", candidates_.bytes()},
          {"pair_factors", factors_.capacity() * sizeof(float) + tile_factors_.bytes()},
          {"kernel_slopes", slopes_.capacity() * sizeof(KernelSlope)},
          {"cell_grid", grid_.bytes()},
          {"per_particle_scratch", scratch}};
}

template <int D>
void RateEvaluator<D>::refresh_ghosts(Particles<D>& p, GhostStage stage) {
  if (!domain_) return;
  ScopedPhase t(timers_, "communication");
  domain_->refresh_ghosts(p, stage);
}

template class RateEvaluator<2>;
template class RateEvaluator<3>;

}  // namespace sphdisk
