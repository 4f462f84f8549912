#pragma once
// One evaluation of the time derivatives, the function the integrators call (through RateSource,
// integrate/rate_source.hpp). Its stages, each under its phase timer (rate_evaluator.cpp, top to
// bottom): choose the pair source (stored lists or pairs searched anew, one h or adaptive h) ->
// search, with the h solve where h is adaptive (adaptive_search.cpp) -> density -> ghosts' halo ->
// velocity gradient and stress -> halo -> heating -> forces (pair_loops). A block step's partial
// evaluation may run them on the particles the active ones involve (partial_evaluation.cpp).
// Reads: pos, vel, mass, u, id, h. Writes: h (adaptive smoothing), rho, stress, acc, du_dt.
#include <atomic>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/particles.hpp"
#include "parallel/timers.hpp"
#include "domain/particle_domain.hpp"
#include "integrate/rate_source.hpp"
#include "neighbours/candidate_filter.hpp"
#include "neighbours/cell_grid.hpp"
#include "neighbours/neighbour_lists.hpp"
#include "neighbours/pair_lists.hpp"
#include "neighbours/tile_half_lists.hpp"
#include "physics/density.hpp"
#include "physics/kernels.hpp"
#include "physics/pair_factors.hpp"
#include "physics/forces.hpp"
#include "physics/physics_params.hpp"
#include "physics/scatter_density.hpp"
#include "physics/viscous_stress.hpp"

namespace sphdisk {

enum class Smoothing {
  Constant,  // one global h for all particles and times (P98 sec. 5.3)
  Adaptive,  // h_i = eta (m_i / rho_i)^(1/D) (physics/smoothing_length.hpp)
};

Smoothing smoothing_from_name(std::string_view name);

enum class PairStorage {
  Stored,  // neighbour lists and pair factors built once per evaluation, read by every pair loop (pair_lists.hpp)
  Rescan,  // nothing stored: the pair loops search their pairs anew (pair_scan.hpp); less memory, slower
};

PairStorage pair_storage_from_name(std::string_view name);


template <int D>
class RateEvaluator final : public RateSource<D> {
 public:
  // h: the global smoothing length (Constant), or the typical one (Adaptive: cell size of the
  // reorder grid). neighbours: the target neighbour number that sets eta (Adaptive).
  RateEvaluator(KernelType kernel, double h, PhysicsParams phys, PhaseTimers& timers,
                Smoothing smoothing = Smoothing::Constant, double neighbours = 60.0);

  using RateSource<D>::evaluate;  // evaluate(p): all particles
  // Block timesteps: only the first `active` particles get new h, rho, stress, acc and du_dt; the
  // others keep their values and count as neighbours with them (as ghosts do). Every pair with an
  // active particle is still evaluated (r < 2 max(h_i, h_j)). With few active particles (one
  // process, stored lists) the evaluation works on a copy of the particles it involves
  // (neighbours/involved_particles.hpp) on the whole set's cell lattice and tiles: the same bits
  // as over all particles, at a cost that follows the active ones.
  void evaluate(Particles<D>& p, std::size_t active) override;
  // Another evaluation of the same first `active` particles at the positions of the last one, with
  // other velocities (the stages of a super-step, integrate/super_steps.hpp). With adaptive h, h and
  // rho stay those of the last evaluation (they depend on the positions alone; the h history is
  // left as it was), so every stage applies the same viscous operator to new velocities, and the
  // cells keep their size (on one process with pairs searched anew the cells themselves are kept,
  // renumbered by `moved`): no smoothing-length solve, only the pair loops and what they need.
  void evaluate_again(Particles<D>& p, std::size_t active, std::span<const std::uint32_t> moved) override;

  // Particles spread over processes (distributed_domain.hpp): evaluate() then adds ghosts, builds
  // its cells on the shared lattice, refreshes the ghosts between passes and removes them again.
  // Null: one process holds all particles.
  void set_domain(ParticleDomain<D>* domain) { domain_ = domain; }
  ParticleDomain<D>* domain() const { return domain_; }
  // Smallest / largest over all processes (timestep and error norms of the integrators).
  double global_min(double x) const override { return domain_ ? domain_->min(x) : x; }
  double global_max(double x) const override { return domain_ ? domain_->max(x) : x; }

  // Whether acc includes the point mass's gravity (default) or only the hydrodynamic part (for an
  // integrator that substeps gravity itself: the r-RESPA leapfrog, integrate/leapfrog.cpp, and the
  // block leapfrog, integrate/block_leapfrog.cpp).
  void include_gravity(bool yes) override { gravity_ = yes; }
  bool includes_gravity() const { return gravity_; }

  // Frees what every evaluation builds anew (cells, lists, tile order, scratch): called before the
  // particles are reordered, so that the reorder's copies of the fields do not come on top of it
  // (the peak memory of a run, docs/performance.md, "Memory per particle"). The next evaluation
  // allocates it again.
  void release_rebuilt_memory();
  std::size_t list_builds() const { return list_builds_; }  // evaluations that built stored lists

  // Whether the pair loops read stored lists or search their pairs anew (PairStorage).
  void set_pair_storage(PairStorage s) { storage_ = s; }
  PairStorage pair_storage() const { return storage_; }
  // Rescan is the mode for runs that would not fit otherwise: its per-particle scratch sized by the
  // particles given new rates (gradient sums, search radii) is also freed after each use, so that
  // its pages come fresh for each evaluation but it is not held with the rest (the peak memory).
  // The force loop's 1/rho, sized by all particles, is kept: refaulting it in every partial
  // evaluation would slow block steps (docs/performance.md, "Memory per particle").
  bool lean() const { return storage_ == PairStorage::Rescan; }

  double smoothing_length() const { return h_; }
  Smoothing smoothing() const { return smoothing_; }
  const PhysicsParams& physics() const override { return phys_; }
  KernelType kernel() const { return kernel_; }
  PhaseTimers& timers() override { return timers_; }
  // Adaptive h: every particle's gather list (|x_i - x_j| < 2 h_i) of the last evaluation.
  // Constant h searches each pair once (pair_lists()) and leaves these empty.
  const NeighbourLists& neighbours() const { return candidates_; }
  // Each interacting pair once (pair_lists.hpp), as the pair loops of the last evaluation read them.
  const PairLists& pair_lists() const { return pairs_lists_; }
  // Indexed by pair_lists' pairs; empty where the lists hold their factors per tile (the density
  // summed during the search, below).
  const PairFactors& pair_factors() const { return factors_; }
  // With one smoothing length and stored lists built afresh, the search runs on the pair loops'
  // schedule and sums the density on its way (neighbours/tile_half_lists.hpp; on by default). Off:
  // a separate density loop over the stored lists, with the same bits (a reference for the tests).
  void set_density_in_search(bool on) { density_in_search_ = on; }
  // Eq. 8's velocity gradient and the moment matrix of the particles given new rates (viscous_stress.hpp);
  // empty after a lean() evaluation.
  const GradientSumsArray<D>& gradient_sums() const { return gradient_sums_; }
  std::size_t evaluations() const { return evaluations_; }
  std::size_t pair_interactions() const { return pairs_; }  // pairs evaluated (each once per pair loop), summed over evaluations
  std::size_t particle_updates() const { return updates_; }  // particles given new rates, summed over evaluations
  std::size_t halo_widenings() const { return halo_widenings_; }  // adaptive h solves repeated with more ghosts
  // Partial evaluations made on the involved particles only, and those repeated with more of them
  // (an active particle's h solve searched beyond them).
  std::size_t involved_evaluations() const { return involved_evaluations_; }
  std::size_t involved_widenings() const { return involved_widenings_; }
  // Whether partial evaluations may work on the involved particles (default; false: always on all,
  // which gives the same bits and is what the tests compare with).
  void set_partial_on_involved(bool yes) { involved_enabled_ = yes; }
  // Adaptive h: particles that solved for h, and the density sums their solves took (one per
  // Newton iterate, a repeated wider search included), summed over evaluations.
  std::size_t smoothing_length_solves() const { return smoothing_length_solves_; }
  std::size_t smoothing_length_sums() const { return smoothing_length_sums_; }
  // Memory held between evaluations, by part (bytes; capacities, scratch included): what the
  // bytes-per-particle figure of a run is made of.
  std::vector<std::pair<std::string, std::size_t>> memory() const;

 private:
  // The evaluation over all of p (false: a search went beyond whole_.complete_radius; nothing done).
  bool evaluate_particles(Particles<D>& p, std::size_t active);
  // The evaluation on the particles the active ones involve (false: not worth it, nothing done).
  bool evaluate_involved(Particles<D>& p, std::size_t active);
  // Adaptive h: the h solve during the search, then the pairs (adaptive_search.cpp; false: a search
  // went beyond whole_.complete_radius).
  bool adaptive_lists(Particles<D>& p, std::size_t active);
  template <class K>
  bool adaptive_lists_with(K kernel, Particles<D>& p, std::size_t active);
  // The pair source's search and the pair loops (rate_evaluator.cpp); each returns the pairs evaluated.
  template <class K>
  std::size_t adaptive_h_pairs(K kernel, Particles<D>& p);
  template <class K>
  std::size_t constant_h_pairs(K kernel, Particles<D>& p, std::size_t active);
  void refresh_ghosts(Particles<D>& p, GhostStage stage);
  // After the lists (Stored) or the tile order (Rescan): density, stress and forces over `pairs`;
  // density(pairs) runs the density loop.
  template <class Pairs, class Density>
  void pair_loops(Particles<D>& p, const Pairs& pairs, Density&& density);
  // Rescan: the tile order for pairs searched anew, and which grid slots hold writable particles.
  void scan_order(const std::vector<Vec<D>>& pos, std::size_t writable);
  int tile_cells() const;

  KernelType kernel_;
  double h_;
  PhysicsParams phys_;
  PhaseTimers& timers_;
  Smoothing smoothing_;
  double eta_;
  CellGrid<D> grid_;       // kept between evaluations to reuse its memory
  ParticleDomain<D>* domain_ = nullptr;
  NeighbourLists candidates_;   // Adaptive: gather candidates of the smoothing-length solve
  std::vector<double> search_radius_;
  // What a super-step stage (evaluate_again, adaptive h) takes from the evaluation before it: the
  // cell size and the tiles' span, and whether grid_ holds the cells of all particles on one process.
  struct KeptSearch {
    bool valid = false;
    double cell_size = 0;
    double widest_support = 0;
    bool grid_of_all = false;
  } kept_;
  bool stage_ = false;                       // inside evaluate_again: h and rho stay
  std::span<const std::uint32_t> moved_;     // evaluate_again's renumbering of the particles
  std::vector<double> need_, reach_, h_start_, halo_short_;  // Adaptive with a domain: halo radii
  std::vector<KernelSlope> slopes_;  // Adaptive: each particle's kernel slope (density.hpp)
  PairStorage storage_ = PairStorage::Stored;
  PairLists pairs_lists_;  // the interacting pairs, each once (pair_lists.hpp); Rescan: the tile order only
  CandidateFilter writable_filter_;  // Rescan: where the writable particles are (candidate_filter.hpp)
  double widest_support_ = 0;  // support radius that the pair schedule's tiles span
  PairFactors factors_;    // kernel-gradient factor of every pair (pair_factors.hpp)
  TileFactors tile_factors_;  // or per tile, where the density is summed during the search
  bool density_in_search_ = true;
  GradientSumsArray<D> gradient_sums_;
  std::vector<Mat<D>> heating_scratch_;
  ForceScratch force_scratch_;
  ScatterDensityScratch scatter_scratch_;
  bool gravity_ = true;
  std::size_t evaluations_ = 0;
  std::size_t pairs_ = 0;
  std::size_t updates_ = 0;
  std::size_t halo_widenings_ = 0;
  std::size_t smoothing_length_solves_ = 0;
  std::size_t smoothing_length_sums_ = 0;
  // Each particle's kernel sums in the current h solve, added up after it: not one shared counter,
  // whose cache line the threads would contend for.
  std::vector<std::uint32_t> solve_sums_;
  std::size_t list_builds_ = 0;
  // A partial evaluation on the involved particles (evaluate_involved) takes these choices from the
  // whole set, so that its cells, neighbour order, tiles and sums are those of an evaluation over
  // all particles (the lattice is shared as between ranks, cell_grid.hpp).
  struct WholeSet {
    bool set = false;
    Lattice<D> lattice;
    double widest_support = 0;   // what the tiles span
    double uniform_mass = 0;     // uniform_mass_of all particles
    std::vector<double> complete_radius;  // every particle within complete_radius[i] of active particle i is involved
  };
  WholeSet whole_;
  std::atomic<bool> search_short_{false};  // an h solve wanted more than whole_.complete_radius
  Particles<D> involved_;                  // the involved particles (kept: reused memory)
  std::vector<std::uint32_t> members_;     // their indices in the whole set, active ones first
  std::vector<double> predicted_h_;        // the whole set's h, active ones' predicted
  bool involved_enabled_ = true;
  std::size_t involved_evaluations_ = 0;
  std::size_t involved_widenings_ = 0;
};

}  // namespace sphdisk
