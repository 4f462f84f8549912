#include "domain/distributed_domain.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <type_traits>

#include "core/error.hpp"

namespace sphdisk {

using namespace packing;

// The lattice over every rank's particles, exactly as one process would build it over all of them
// (min and max are exact, so the corner and cell size have the same bits), and a top grid on it of
// about max(top_cells_per_rank x ranks, particles / particles_per_top_cell) cells.
template <int D>
Decomposition<D> global_top_grid(const Communicator& comm, const Particles<D>& p, double min_cell_size,
                                 std::size_t top_cells_per_rank, std::size_t particles_per_top_cell = 0) {
  std::array<double, D> lo, hi;
  lo.fill(std::numeric_limits<double>::max());
  hi.fill(std::numeric_limits<double>::lowest());
  for (const Vec<D>& x : p.pos)
    for (int k = 0; k < D; ++k) {
      lo[static_cast<std::size_t>(k)] = std::min(lo[static_cast<std::size_t>(k)], x[k]);
      hi[static_cast<std::size_t>(k)] = std::max(hi[static_cast<std::size_t>(k)], x[k]);
    }
  comm.min(lo);
  comm.max(hi);
  const std::uint64_t n = comm.sum(p.size());
  if (n == 0) throw UserError("no particles left on any rank");
  Vec<D> vlo, vhi;
  for (int k = 0; k < D; ++k) {
    vlo[k] = lo[static_cast<std::size_t>(k)];
    vhi[k] = hi[static_cast<std::size_t>(k)];
  }
  std::size_t cells = top_cells_per_rank * static_cast<std::size_t>(comm.size());
  if (particles_per_top_cell > 0) cells = std::max<std::size_t>(cells, n / particles_per_top_cell);
  return make_top_grid(make_lattice(vlo, vhi, n, min_cell_size), cells);
}

template <int D>
Decomposition<D> decompose(const Communicator& comm, const Particles<D>& p, double min_cell_size,
                           std::size_t top_cells_per_rank) {
  Decomposition<D> d = global_top_grid(comm, p, min_cell_size, top_cells_per_rank);
  std::vector<std::uint64_t> counts(d.top_cells(), 0);
  for (const Vec<D>& x : p.pos) ++counts[d.top_cell_of(x)];
  comm.sum(counts);
  assign_owners(d, counts, comm.size());
  return d;
}

// Particles move in rounds of at most this many per destination, so that the packed copies on
// both sides stay small next to the particles themselves, even at the first distribution (after
// reading a file by slices, about (P-1)/P of them move) and when regrouping for output.
constexpr std::size_t kRound = std::size_t{1} << 15;

// Sends the particles to[r] of p to rank r (only `fields`) and appends the arrivals to out, which
// may be p itself (it is resized once, before anything is read). Returns how many arrived.
template <int D>
std::size_t send_in_rounds(const Communicator& comm, const Particles<D>& p, const std::vector<std::vector<std::uint32_t>>& to,
                           const FieldNames& fields, Particles<D>& out) {
  const auto ranks = static_cast<std::size_t>(comm.size());
  // How many come from each rank (an all-to-all of counts), and the largest count of any rank to
  // any rank, which sets the rounds all take.
  std::vector<std::uint64_t> sending(ranks), busiest(1, 0);
  for (std::size_t r = 0; r < ranks; ++r) {
    sending[r] = to[r].size();
    busiest[0] = std::max(busiest[0], sending[r]);
  }
  std::uint64_t arriving = 0;
  for (const std::uint64_t c : comm.all_to_all(sending)) arriving += c;
  comm.max(std::span<std::uint64_t>(busiest));
  std::size_t next = out.size();
  out.resize(out.size() + arriving);
  for (std::size_t start = 0; start < busiest[0]; start += kRound) {
    std::vector<std::vector<std::byte>> send(ranks);
    for (std::size_t r = 0; r < ranks; ++r) {
      if (start >= to[r].size()) continue;
      const auto first = to[r].begin() + static_cast<std::ptrdiff_t>(start);
      const auto last = to[r].begin() + static_cast<std::ptrdiff_t>(std::min(to[r].size(), start + kRound));
      send[r] = pack(p, std::vector<std::uint32_t>(first, last), fields);
    }
    for (const auto& buf : comm.exchange(send)) {
      unpack(out, next, buf, fields);
      next += packed_count(buf);
    }
  }
  return arriving;
}

// The owner of each particle under d.
template <int D>
std::vector<int> owners_of(const Decomposition<D>& d, const Particles<D>& p) {
  std::vector<int> owner(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) owner[i] = d.owner_of(p.pos[i]);
  return owner;
}

// Sends particle i to rank owner[i].
template <int D>
void migrate_to(const Communicator& comm, const std::vector<int>& owner, Particles<D>& p) {
  std::vector<std::vector<std::uint32_t>> leaving(static_cast<std::size_t>(comm.size()));
  std::vector<std::uint32_t> keep;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const int r = owner[i];
    (r == comm.rank() ? keep : leaving[static_cast<std::size_t>(r)]).push_back(static_cast<std::uint32_t>(i));
  }
  const std::size_t arrived = send_in_rounds(comm, p, leaving, {}, p);  // appended after the leavers
  for (std::size_t i = p.size() - arrived; i < p.size(); ++i) keep.push_back(static_cast<std::uint32_t>(i));
  p.gather(keep);
}

template <int D>
void migrate(const Communicator& comm, const Decomposition<D>& d, Particles<D>& p) {
  migrate_to(comm, owners_of(d, p), p);
}

// Rank of each ID's range: P equal ranges over [0, max ID of all ranks].
std::function<std::size_t(std::uint64_t)> id_range_of(const Communicator& comm, const std::vector<std::uint64_t>& ids) {
  const auto ranks = static_cast<std::size_t>(comm.size());
  std::uint64_t max_id = 0;
  for (const std::uint64_t id : ids) max_id = std::max(max_id, id);
  std::vector<std::uint64_t> global{max_id};
  comm.max(std::span<std::uint64_t>(global));
  const std::uint64_t width = global[0] / ranks + 1;  // IDs per range: r = id / width < ranks
  return [width, ranks](std::uint64_t id) { return std::min<std::size_t>(id / width, ranks - 1); };
}

template <int D>
Particles<D> regroup_by_id(const Communicator& comm, const Particles<D>& p, const FieldNames& fields) {
  const auto range_of = id_range_of(comm, p.id);
  std::vector<std::vector<std::uint32_t>> to(static_cast<std::size_t>(comm.size()));
  for (std::size_t i = 0; i < p.size(); ++i) to[range_of(p.id[i])].push_back(static_cast<std::uint32_t>(i));
  FieldNames with_id = fields;
  if (!selected(fields, "id")) with_id.push_back("id");
  Particles<D> out;
  out.set_absent_fields(p.absent_fields());
  send_in_rounds(comm, p, to, with_id, out);
  std::vector<std::uint32_t> order(out.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&out](std::uint32_t a, std::uint32_t b) { return out.id[a] < out.id[b]; });
  out.gather(order);
  return out;
}

bool ids_unique(const Communicator& comm, const std::vector<std::uint64_t>& ids) {
  const auto range_of = id_range_of(comm, ids);
  std::vector<std::vector<std::uint64_t>> to(static_cast<std::size_t>(comm.size()));
  for (const std::uint64_t id : ids) to[range_of(id)].push_back(id);
  std::vector<std::vector<std::byte>> send(to.size());
  for (std::size_t r = 0; r < to.size(); ++r) {
    const auto* bytes = reinterpret_cast<const std::byte*>(to[r].data());
    send[r].assign(bytes, bytes + to[r].size() * sizeof(std::uint64_t));
  }
  std::vector<std::uint64_t> mine;
  for (const auto& buf : comm.exchange(send)) {
    const std::size_t n = buf.size() / sizeof(std::uint64_t);
    if (n == 0) continue;  // (memcpy from an empty buffer's null data is undefined)
    mine.resize(mine.size() + n);
    std::memcpy(mine.data() + mine.size() - n, buf.data(), buf.size());
  }
  std::sort(mine.begin(), mine.end());
  return !comm.any(std::adjacent_find(mine.begin(), mine.end()) != mine.end());
}

Traffic DomainTraffic::total() const {
  Traffic t = migration;
  t += halo_build;
  t += halo_refresh;
  t += reductions;
  return t;
}

namespace {
// Adds what f() sends to `into`.
template <class F>
void count_traffic(Traffic& into, F&& f) {
  const Traffic before = sent_traffic();
  f();
  into += sent_traffic() - before;
}
}  // namespace

template <int D>
void DistributedDomain<D>::rebalance(Particles<D>& p, double min_cell_size) {
  if (comm_.size() == 1) return;
  count_traffic(traffic_.migration, [&] { rebalance_now(p, min_cell_size); });
}

template <int D>
void DistributedDomain<D>::rebalance_now(Particles<D>& p, double min_cell_size) {
  auto imbalance_of = [&](const std::vector<int>& owner) {
    std::vector<std::uint64_t> counts(static_cast<std::size_t>(comm_.size()), 0);
    for (const int r : owner) ++counts[static_cast<std::size_t>(r)];
    comm_.sum(counts);
    const std::uint64_t total = std::accumulate(counts.begin(), counts.end(), std::uint64_t{0});
    return static_cast<double>(*std::max_element(counts.begin(), counts.end())) * static_cast<double>(counts.size()) /
           static_cast<double>(std::max<std::uint64_t>(total, 1));
  };
  std::vector<int> owner;
  if (owners_) {  // particles outside the old lattice go to its edge cells
    owner = owners_of(*owners_, p);
    imbalance_ = imbalance_of(owner);
  }
  if (!owners_ || imbalance_ > threshold_) {
    owners_ = decompose(comm_, p, min_cell_size, top_cells_per_rank_);
    owner = owners_of(*owners_, p);
    imbalance_ = imbalance_of(owner);
    ++recuts_;
  }
  migrate_to(comm_, owner, p);
}

template <int D>
Lattice<D> DistributedDomain<D>::add_ghosts(Particles<D>& p, double min_cell_size, const RadiusOf& need,
                                            const RadiusOf& reach) {
  // The halo's top cells are finer than the decomposition's (a few lattice cells across): ghosts
  // are chosen by distance to whole top cells, so coarse ones would bring many spare ghosts.
  constexpr std::size_t kParticlesPerHaloCell = 8;
  const Traffic before = sent_traffic();
  const Decomposition<D> grid = global_top_grid(comm_, p, min_cell_size, top_cells_per_rank_, kParticlesPerHaloCell);
  halo_.build(comm_, grid, p, need, reach);
  traffic_.halo_build += sent_traffic() - before;
  return grid.lattice;
}

template <int D>
double DistributedDomain<D>::kth_smallest(const std::vector<double>& values, std::uint64_t k) const {
  // Radix selection on the bit patterns (non-negative doubles order as their bits), one byte per
  // round from the top: an exact answer from 8 small histograms, whatever the rank count.
  const Traffic before = sent_traffic();
  std::uint64_t prefix = 0, rank_in = k;
  for (int shift = 56; shift >= 0; shift -= 8) {
    const std::uint64_t high_mask = shift == 56 ? 0 : ~std::uint64_t{0} << (shift + 8);
    std::vector<std::uint64_t> hist(256, 0);
    for (const double v : values) {
      std::uint64_t b;
      std::memcpy(&b, &v, sizeof b);
      if ((b & high_mask) == prefix) ++hist[(b >> shift) & 0xffu];
    }
    comm_.sum(hist);
    std::size_t bin = 0;
    while (bin < 255 && rank_in >= hist[bin]) rank_in -= hist[bin++];
    prefix |= static_cast<std::uint64_t>(bin) << shift;
  }
  double out;
  std::memcpy(&out, &prefix, sizeof out);
  traffic_.reductions += sent_traffic() - before;
  return out;
}

template <int D>
void DistributedDomain<D>::refresh_ghosts(Particles<D>& p, GhostStage stage) {
  const Traffic before = sent_traffic();
  switch (stage) {
    case GhostStage::SmoothingLength: halo_.refresh(comm_, p, kHaloSmoothingLength); break;
    case GhostStage::Density: halo_.refresh(comm_, p, kHaloDensity); break;
    case GhostStage::Stress: halo_.refresh(comm_, p, kHaloStress); break;
  }
  traffic_.halo_refresh += sent_traffic() - before;
}

template class DistributedDomain<2>;
template class DistributedDomain<3>;
template Decomposition<2> decompose(const Communicator&, const Particles<2>&, double, std::size_t);
template Decomposition<3> decompose(const Communicator&, const Particles<3>&, double, std::size_t);
template void migrate(const Communicator&, const Decomposition<2>&, Particles<2>&);
template void migrate(const Communicator&, const Decomposition<3>&, Particles<3>&);
template Particles<2> regroup_by_id(const Communicator&, const Particles<2>&, const FieldNames&);
template Particles<3> regroup_by_id(const Communicator&, const Particles<3>&, const FieldNames&);

}  // namespace sphdisk
