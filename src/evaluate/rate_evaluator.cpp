#include "evaluate/rate_evaluator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>

#include "core/error.hpp"
#include "core/named_choice.hpp"
#include "core/snug_resize.hpp"
#include "evaluate/cells_and_tiles.hpp"
#include "neighbours/cell_grid.hpp"
#include "neighbours/involved_particles.hpp"
#include "neighbours/pair_lists.hpp"
#include "neighbours/pair_scan.hpp"
#include "parallel/nth_values.hpp"
#include "parallel/trace.hpp"
#include "physics/density.hpp"
#include "physics/forces.hpp"
#include "physics/list_factors.hpp"
#include "physics/smoothing_length.hpp"
#include "physics/viscous_rates.hpp"
#include "physics/viscous_stress.hpp"

namespace sphdisk {

using namespace evaluation;

namespace {
// One trace event per evaluation with the number of particles it gives new rates, so that a trace
// shows where a block cycle's time goes by evaluation size (bench/evaluation_sizes.py reads it).
class EvaluationEvent {
 public:
  EvaluationEvent(std::size_t active, std::size_t particles, bool stage)
      : active_(active), particles_(particles), stage_(stage), begin_(par::trace_enabled() ? par::trace_now_us() : -1) {}
  ~EvaluationEvent() {
    if (begin_ < 0) return;
    char args[96];
    std::snprintf(args, sizeof args, "\"active\":%zu,\"particles\":%zu,\"stage\":%d", active_, particles_, stage_ ? 1 : 0);
    par::trace_record("evaluation", begin_, par::trace_now_us(), args);
  }
  EvaluationEvent(const EvaluationEvent&) = delete;
  EvaluationEvent& operator=(const EvaluationEvent&) = delete;

 private:
  std::size_t active_, particles_;
  bool stage_;
  double begin_;
};

// Pairs searched anew over `grid`, made under the search's timer (the constructor summarises the tiles).
template <int D, class Form>
ScannedPairs<D, Form> timed_scanned_pairs(PhaseTimers& timers, const CellGrid<D>& grid, const PairLists& tiles,
                                          const std::vector<double>& h, bool equal_h, const CandidateFilter& writable,
                                          Form form) {
  ScopedPhase t(timers, "neighbour_search");
  return ScannedPairs<D, Form>(grid, tiles, h, equal_h, writable, form);
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


template <int D>
void RateEvaluator<D>::release_rebuilt_memory() {
  kept_ = {};
  release_memory(grid_, candidates_, search_radius_, slopes_, pairs_lists_,
                 writable_filter_, factors_, gradient_sums_, heating_scratch_, force_scratch_.inv_rho,
                 force_scratch_.p_over_rho2, force_scratch_.log_rho, force_scratch_.rho_without_self, force_scratch_.scales,
                 solve_sums_, involved_, members_, predicted_h_);
}

template <int D>
void RateEvaluator<D>::evaluate(Particles<D>& p, std::size_t active) {
  active = std::min(active, p.size());
  const EvaluationEvent event(active, p.size(), false);
  kept_ = {};
  if (evaluate_involved(p, active)) return;
  evaluate_particles(p, active);
}

template <int D>
void RateEvaluator<D>::evaluate_again(Particles<D>& p, std::size_t active, std::span<const std::uint32_t> moved) {
  active = std::min(active, p.size());
  if (smoothing_ != Smoothing::Adaptive || !kept_.valid) {
    evaluate(p, active);
    return;
  }
  // (Over all particles, not on a copy of the involved ones, which only stored lists use: a stage's
  // search without a solve is light.)
  const EvaluationEvent event(active, p.size(), true);
  stage_ = true;
  moved_ = moved;
  evaluate_particles(p, active);
  stage_ = false;
  moved_ = {};
}


// The stages over all of p (or the involved particles, whole_.set): the pair source that the
// smoothing and the pair storage choose, its search (with the h solve, adaptive h), then the pair
// loops (pair_loops). False: an h solve searched beyond the involved particles; nothing done.
template <int D>
bool RateEvaluator<D>::evaluate_particles(Particles<D>& p, std::size_t active) {
  // Set by a search beyond the involved particles (whole_.set only); cleared here, not where the
  // involved evaluation starts, so that one given up on (too many involved particles) leaves no
  // stale flag for the evaluation over all particles that follows.
  search_short_ = false;
  const std::optional<std::size_t> pairs = with_kernel(kernel_, [&](auto kernel) -> std::optional<std::size_t> {
    if (smoothing_ == Smoothing::Constant) return constant_h_pairs(kernel, p, active);
    if (!adaptive_lists(p, active)) return std::nullopt;  // the h solve in the search (adaptive_search.cpp)
    return adaptive_h_pairs(kernel, p);
  });
  if (!pairs) return false;
  ++evaluations_;
  if (domain_) domain_->remove_ghosts(p);
  pairs_ += *pairs;
  updates_ += active;
  return true;
}

template <int D>
template <class Pairs, class Density>
void RateEvaluator<D>::pair_loops(Particles<D>& p, const Pairs& pairs, Density&& density) {
  static_assert(PairSource<Pairs>);
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
      compute_stress_and_accelerations(p, pairs, phys_, gradient_sums_, force_scratch_, scatter_scratch_, gravity_);
      if (lean()) release_memory(gradient_sums_, scatter_scratch_.scales, scatter_scratch_.sums);
      return;
    }
  }
  {
    ScopedPhase t(timers_, "velocity_gradient");
    compute_viscous_stress(p, pairs, phys_, gradient_sums_, force_scratch_.scales, scatter_scratch_);
    if (lean()) release_memory(gradient_sums_, scatter_scratch_.scales, scatter_scratch_.sums);
  }
  refresh_ghosts(p, GhostStage::Stress);
  if (corrected_heating) {
    ScopedPhase t(timers_, "velocity_gradient");
    add_force_corrected_heating(p, pairs, heating_scratch_);
  }
  ScopedPhase t(timers_, "forces");
  compute_accelerations(p, pairs, phys_, force_scratch_, gravity_);
}

// Adaptive h, after the search and h solve: the pair loops over pairs searched anew (Rescan) or over
// the stored half lists. Returns the pairs evaluated.
template <int D>
template <class K>
std::size_t RateEvaluator<D>::adaptive_h_pairs(K, Particles<D>& p) {
  if (storage_ == PairStorage::Rescan) {
    // No per-particle kernels kept either: each is made from h where needed (the same values).
    const auto form = [&p](std::uint32_t i, std::span<const std::uint32_t> js, const double* r2, std::span<float> F) {
      factors_from_h<K, D>(p.h[i], p.h.data(), js, r2, F);
    };
    const auto scanned = timed_scanned_pairs(timers_, grid_, pairs_lists_, p.h, false, writable_filter_, form);
    pair_loops(p, scanned, [&](const auto& pairs) { set_volumes(p, pairs.writable()); });
    return scanned.pairs_found();
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
  return pairs_lists_.total();
}

// One h for all particles: the cells (on the shared lattice over ranks, or the whole set's for the
// involved particles), the search, then the pair loops. Returns the pairs evaluated.
template <int D>
template <class K>
std::size_t RateEvaluator<D>::constant_h_pairs(K, Particles<D>& p, std::size_t active) {
  const double support = 2.0 * h_;  // all kernels have compact support 2h
  widest_support_ = support;
  if (domain_) {
    Lattice<D> lattice;
    {
      ScopedPhase t(timers_, "communication");
      const auto radius = [support](std::size_t) { return support; };
      // (Inactive particles pair with no ghost: they draw none, add_ghosts.)
      const auto need = [support, active](std::size_t i) { return i < active ? support : -1.0; };
      lattice = domain_->add_ghosts(p, 0.5 * support, need, radius);
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
  const bool rescan = storage_ == PairStorage::Rescan;
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
    return pairs_lists_.total();
  }
  if (rescan) {
    const auto form = [kern](std::uint32_t, std::span<const std::uint32_t> js, const double* r2, std::span<float> F) {
      for (std::size_t q = 0; q < js.size(); ++q) F[q] = static_cast<float>(kern.dW_over_r(std::sqrt(r2[q])));
    };
    const auto scanned = timed_scanned_pairs(timers_, grid_, pairs_lists_, p.h, true, writable_filter_, form);
    pair_loops(p, scanned, density);
    return scanned.pairs_found();
  }
  pair_loops(p, StoredPairs{pairs_lists_, factors_}, density);
  return pairs_lists_.total();
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
  for (const auto* v : {&search_radius_, &need_, &reach_, &h_start_, &halo_short_}) scratch += v->capacity() * sizeof(double);
  scratch += gradient_sums_.bytes() + heating_scratch_.capacity() * sizeof(Mat<D>) +
             (force_scratch_.inv_rho.capacity() + force_scratch_.p_over_rho2.capacity() + force_scratch_.log_rho.capacity() +
              force_scratch_.rho_without_self.capacity() + 2 * force_scratch_.scales.capacity() +
              scatter_scratch_.sums.capacity() + 2 * scatter_scratch_.scales.capacity()) *
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
