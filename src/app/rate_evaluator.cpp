#include "app/rate_evaluator.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "neighbours/cell_grid.hpp"
#include "neighbours/interaction_lists.hpp"
#include "physics/density.hpp"
#include "physics/forces.hpp"
#include "physics/smoothing_length.hpp"
#include "physics/viscous_stress.hpp"

namespace sphdisk {

namespace {

// Candidates are searched to kSkin x 2 h_i, so h may grow by kSkin while it is solved for before
// the particle's search must be repeated.
constexpr double kSkin = 1.05;

// The median h sets the cell size: the denser particles scan few cells and the rest
// (larger h) reach over more cells; any cell size gives the same lists.
double cell_size_for(const std::vector<double>& h) {
  std::vector<double> sorted(h);
  const auto k = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
  std::nth_element(sorted.begin(), k, sorted.end());
  return kSkin * *k;
}

}  // namespace

Smoothing smoothing_from_name(std::string_view name) {
  if (name == "constant") return Smoothing::Constant;
  if (name == "adaptive") return Smoothing::Adaptive;
  throw UserError("unknown smoothing '" + std::string(name) + "'; use constant or adaptive");
}

template <int D>
RateEvaluator<D>::RateEvaluator(KernelType kernel, double h, PhysicsParams phys, PhaseTimers& timers,
                                Smoothing smoothing, double neighbours)
    : kernel_(kernel), h_(h), phys_(phys), timers_(timers), smoothing_(smoothing),
      eta_(eta_for_neighbours<D>(neighbours)) {}

// Solves h_i while searching each particle's neighbours (widening the search where the solution
// lies beyond it), then builds the symmetric interaction lists (interaction_lists.hpp).
template <int D>
template <class K>
void RateEvaluator<D>::adaptive_lists(Particles<D>& p) {
  search_radius_.resize(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) search_radius_[i] = 2.0 * kSkin * p.h[i];
  {
    ScopedPhase t(timers_, "cell_build");
    build_cell_grid(p.pos, p.id, cell_size_for(p.h), grid_);
  }
  double extent = 0;  // a search beyond twice the grid's diagonal cannot find more particles
  for (int k = 0; k < D; ++k) extent += std::pow(grid_.cell_size * grid_.dims[static_cast<std::size_t>(k)], 2);
  const double widest = 4.0 * std::sqrt(extent);
  const SettleRadius settle = [&](std::size_t i, std::span<const std::uint32_t> cand, double searched) {
    const SmoothingLengthResult r = smoothing_length_at<K, D>(i, p, cand, p.h[i], eta_, 0.5 * searched);
    if (r.beyond_candidates && searched < widest) {
      p.h[i] = r.h;  // the start value of the wider search
      return 2.0 * kSkin * r.h;
    }
    p.h[i] = r.beyond_candidates ? 0.5 * searched : r.h;  // too few particles in the whole domain: keep all
    return 2.0 * p.h[i];
  };
  {
    ScopedPhase t(timers_, "neighbour_search");
    build_settled_neighbour_lists(grid_, p.pos, search_radius_, settle, candidates_);
  }
  ScopedPhase t(timers_, "neighbour_search");
  build_interaction_lists(candidates_, p.pos, p.h, p.id, lists_);
}

template <int D>
void RateEvaluator<D>::evaluate(Particles<D>& p) {
  with_kernel(kernel_, [&](auto k) {
    using K = decltype(k);
    if (smoothing_ == Smoothing::Adaptive) {
      if (domain_) throw UserError("adaptive smoothing lengths are not yet supported on more than one MPI rank; set sph.smoothing = \"constant\" or run on one rank");
      adaptive_lists<K>(p);
      ScopedPhase t(timers_, "density");
      compute_density(p, lists_, std::get<std::vector<KernelAt<K, D>>>(kernels_), factors_);
      return;
    }
    const double support = 2.0 * h_;  // all kernels have compact support 2h
    if (domain_) {
      Lattice<D> lattice;
      {
        ScopedPhase t(timers_, "communication");
        lattice = domain_->add_ghosts(p, 0.5 * support, support);
      }
      std::fill(p.h.begin(), p.h.end(), h_);  // what the timestep criteria and the snapshots read
      ScopedPhase t(timers_, "cell_build");
      build_cell_grid(lattice, p.pos, p.id, grid_);
    } else {
      std::fill(p.h.begin(), p.h.end(), h_);
      ScopedPhase t(timers_, "cell_build");
      build_cell_grid(p.pos, p.id, 0.5 * support, grid_);
    }
    {
      ScopedPhase t(timers_, "neighbour_search");
      build_neighbour_lists(grid_, p.pos, support, lists_);
    }
    ScopedPhase t(timers_, "density");
    compute_density(p, lists_, KernelAt<K, D>(h_), factors_);
  });
  refresh_ghosts(p, GhostStage::Density);
  {
    ScopedPhase t(timers_, "velocity_gradient");
    compute_viscous_stress(p, lists_, factors_, phys_);
  }
  refresh_ghosts(p, GhostStage::Stress);
  if (phys_.force_correction) {
    ScopedPhase t(timers_, "velocity_gradient");
    add_force_corrected_heating(p, lists_, factors_);
  }
  {
    ScopedPhase t(timers_, "forces");
    compute_accelerations(p, lists_, factors_, phys_);
  }
  ++evaluations_;
  if (domain_) domain_->remove_ghosts(p);
  pairs_ += lists_.offsets[p.size()];  // owned particles' pairs (ghosts' lists are scratch)
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
