// Partial evaluations of block timesteps on the particles the active ones involve
// (neighbours/involved_particles.hpp): the same bits as an evaluation over all particles, at a cost
// that follows the active ones.
#include "evaluate/cells_and_tiles.hpp"
#include "evaluate/rate_evaluator.hpp"
#include "neighbours/cell_grid.hpp"
#include "neighbours/involved_particles.hpp"
#include "physics/smoothing_length.hpp"

namespace sphdisk {

using namespace evaluation;

namespace {

// Partial evaluations with at most this fraction of the particles active work on the involved
// particles (evaluate_involved), unless these are more than kInvolvedMost of all. Either way the
// bits are the same. With few active particles this halves an evaluation; with more, the involved
// particles are a large part of all, and copying them, searching them and the occasional repeat
// cost more than the work over all particles they spare (docs/performance.md, "Block timesteps").
constexpr double kInvolvedActive = 0.02;
constexpr double kInvolvedMost = 0.5;

}  // namespace

// The choices evaluate_particles makes from all particles (cell size and lattice, the tiles' span,
// the common mass) are made here first, and the evaluation on the involved particles takes them
// (whole_): every cell lies where it lies in the whole set's grid, so candidates, lists and tiles
// come in the same order and every sum takes the same terms in the same order. The involved set
// holds every particle within complete_radius[i] of each active particle i (involved_particles.hpp):
// with adaptive h that covers its first search (2 kSkin h from its predicted h) with kHaloMargin
// to spare; a solve that wants a wider search sets search_short_, and the evaluation is repeated
// with twice the radii (as a rank's solve is repeated with more ghosts).
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
      const CellsAndTiles c = cells_and_tiles<D>(predicted_h_);
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

template bool RateEvaluator<2>::evaluate_involved(Particles<2>&, std::size_t);
template bool RateEvaluator<3>::evaluate_involved(Particles<3>&, std::size_t);

}  // namespace sphdisk
