#pragma once
// Particles spread over ranks: decomposition from global counts, migration of particles to their
// owners, and the halo of ghost particles each rank needs for its owned particles' neighbour sums.
// Memory per rank is O(N/P + halo): no rank ever holds all particles (unlike P98's broadcast).
// The halo's ghosts and how they are chosen: domain/halo.hpp.
#include <functional>
#include <initializer_list>
#include <optional>
#include <string_view>
#include <vector>

#include "core/particles.hpp"
#include "domain/decomposition.hpp"
#include "domain/halo.hpp"
#include "domain/particle_packing.hpp"
#include "domain/particle_domain.hpp"
#include "parallel/communicator.hpp"

namespace sphdisk {

// The lattice over all ranks' particles and the top cells cut into equal-count runs.
// min_cell_size as for build_cell_grid; top_cells_per_rank sets the balancing granularity.
template <int D>
Decomposition<D> decompose(const Communicator& comm, const Particles<D>& p, double min_cell_size,
                           std::size_t top_cells_per_rank = 256);

// Sends every particle to the rank owning its top cell. Owned particles only (no ghosts).
template <int D>
void migrate(const Communicator& comm, const Decomposition<D>& d, Particles<D>& p);

// Copies of the particles regrouped by ID, in ID order: rank r gets the IDs of the r-th of P equal
// ID ranges (for writing files in ID order without gathering them anywhere). Only `fields` (and
// the IDs) are copied; the others are sized but unset.
template <int D>
Particles<D> regroup_by_id(const Communicator& comm, const Particles<D>& p, const FieldNames& fields = {});

// True on every rank when no ID occurs twice among all ranks' `ids` (collective; O(N/P) memory:
// each ID is checked on the rank of its ID range).
bool ids_unique(const Communicator& comm, const std::vector<std::uint64_t>& ids);

// What a DistributedDomain has sent, by purpose (sent_traffic() differences around each call).
struct DomainTraffic {
  Traffic migration;     // particles moved to their owners, with the decomposition's reductions
  Traffic halo_build;    // ghosts chosen (ranks' boxes gathered, cell lists to neighbours) and sent whole
  Traffic halo_refresh;  // ghost fields refreshed between passes
  Traffic reductions;    // the physics' global values (min, max, sums, selections)
  Traffic total() const;
};

// The ParticleDomain of a run over MPI ranks (one rank: no ghosts, no messages).
template <int D>
class DistributedDomain final : public ParticleDomain<D> {
 public:
  // threshold: the particle-count imbalance (largest rank / mean) above which rebalance() cuts the
  // top cells anew (SWIFT's domain-decomposition trigger plays the same role).
  explicit DistributedDomain(Communicator comm, double threshold = 1.05, std::size_t top_cells_per_rank = 256)
      : comm_(comm), threshold_(threshold), top_cells_per_rank_(top_cells_per_rank) {}

  // Between steps: sends every particle to the owner of its top cell. The owners stay as they are
  // while the counts they give stay within the threshold; past it (and the first time) the top
  // cells are cut anew into runs of equal particle count. Collective; the decision uses exact
  // global counts, so every rank takes it alike, and results never depend on it.
  void rebalance(Particles<D>& p, double min_cell_size);
  std::size_t recuts() const { return recuts_; }           // decompositions made so far
  double imbalance() const { return imbalance_; }           // of the owners used at the last rebalance

  Lattice<D> add_ghosts(Particles<D>& p, double min_cell_size, const RadiusOf& need, const RadiusOf& reach) override;
  double kth_smallest(const std::vector<double>& values, std::uint64_t k) const override;
  void refresh_ghosts(Particles<D>& p, GhostStage stage) override;
  void remove_ghosts(Particles<D>& p) override { halo_.drop(p); }
  double min(double x) const override { return counted([&] { return comm_.min(x); }); }
  double max(double x) const override { return counted([&] { return comm_.max(x); }); }
  std::uint64_t sum(std::uint64_t x) const override { return counted([&] { return comm_.sum(x); }); }
  bool any(bool x) const override { return counted([&] { return comm_.any(x); }); }

  const Communicator& comm() const { return comm_; }
  const Halo<D>& halo() const { return halo_; }
  const DomainTraffic& traffic() const { return traffic_; }

 private:
  void rebalance_now(Particles<D>& p, double min_cell_size);
  // f(), with what it sends added to traffic_.reductions.
  template <class F>
  auto counted(F&& f) const {
    const Traffic before = sent_traffic();
    const auto out = f();
    traffic_.reductions += sent_traffic() - before;
    return out;
  }

  Communicator comm_;
  double threshold_;
  std::size_t top_cells_per_rank_;
  Halo<D> halo_;
  std::optional<Decomposition<D>> owners_;
  std::size_t recuts_ = 0;
  double imbalance_ = 1;
  mutable DomainTraffic traffic_;
};

}  // namespace sphdisk
