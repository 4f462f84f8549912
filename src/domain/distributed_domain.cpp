#include "domain/distributed_domain.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <type_traits>

#include "core/error.hpp"
#include "domain/rank_boxes.hpp"
#include "domain/top_cell_set.hpp"

namespace sphdisk {

namespace {

bool selected(const FieldNames& fields, std::string_view name) {
  return fields.empty() || std::find(fields.begin(), fields.end(), name) != fields.end();
}

// Buffer layout: particle count, then each selected field in table order.
template <int D>
std::vector<std::byte> pack(const Particles<D>& p, const std::vector<std::uint32_t>& idx, const FieldNames& fields) {
  std::vector<std::byte> buf(sizeof(std::uint64_t));
  const std::uint64_t n = idx.size();
  std::memcpy(buf.data(), &n, sizeof n);
  p.for_each_field([&](const FieldInfo& info, const auto& v) {
    using T = typename std::remove_reference_t<decltype(v)>::value_type;
    static_assert(std::is_trivially_copyable_v<T>);
    if (!selected(fields, info.name)) return;
    const std::size_t at = buf.size();
    buf.resize(at + idx.size() * sizeof(T));
    for (std::size_t k = 0; k < idx.size(); ++k) std::memcpy(buf.data() + at + k * sizeof(T), &v[idx[k]], sizeof(T));
  });
  return buf;
}

std::uint64_t packed_count(const std::vector<std::byte>& buf) {
  std::uint64_t n = 0;
  if (buf.size() >= sizeof n) std::memcpy(&n, buf.data(), sizeof n);
  return n;
}

// Writes the buffer's particles into p at [first, first + count) (p already large enough).
template <int D>
void unpack(Particles<D>& p, std::size_t first, const std::vector<std::byte>& buf, const FieldNames& fields) {
  const std::uint64_t n = packed_count(buf);
  std::size_t at = sizeof(std::uint64_t);
  p.for_each_field([&](const FieldInfo& info, auto& v) {
    using T = typename std::remove_reference_t<decltype(v)>::value_type;
    if (!selected(fields, info.name)) return;
    if (n > 0) std::memcpy(static_cast<void*>(&v[first]), buf.data() + at, n * sizeof(T));
    at += n * sizeof(T);
  });
}

// Appends every buffer's particles to p.
template <int D>
void unpack_all(Particles<D>& p, const std::vector<std::vector<std::byte>>& bufs, const FieldNames& fields = {}) {
  std::size_t n = p.size();
  for (const auto& buf : bufs) n += packed_count(buf);
  std::size_t first = p.size();
  p.resize(n);
  for (const auto& buf : bufs) {
    unpack(p, first, buf, fields);
    first += packed_count(buf);
  }
}

}  // namespace

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

// Top cells are visited as offsets in a box of half-width `reach` cells around a centre cell.
template <int D, class F>
void for_each_top_cell_near(const Decomposition<D>& grid, const std::array<int, D>& centre, int reach, F&& f) {
  std::array<int, D> c{}, lo_c, hi_c;
  for (int k = 0; k < D; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    lo_c[kk] = std::max(centre[kk] - reach, 0);
    hi_c[kk] = std::min(centre[kk] + reach, grid.top_dims[kk] - 1);
    c[kk] = lo_c[kk];
  }
  for (;;) {
    f(c);
    int k = 0;
    for (; k < D; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      if (++c[kk] <= hi_c[kk]) break;
      c[kk] = lo_c[kk];
    }
    if (k == D) return;
  }
}

template <int D>
std::array<int, D> coord_of_index(const Decomposition<D>& grid, std::size_t index) {
  std::array<int, D> t{};
  for (int k = 0; k < D; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    t[kk] = static_cast<int>(index % static_cast<std::size_t>(grid.top_dims[kk]));
    index /= static_cast<std::size_t>(grid.top_dims[kk]);
  }
  return t;
}

// This rank's boxes (domain/rank_boxes.hpp), gathered from all ranks: its particles with their
// largest reach, its reading cells (`cells`: cell and need) as distance2_to bounds them.
template <int D, class Cells>
std::vector<RankBoxes<D>> gather_rank_boxes(const Communicator& comm, const Decomposition<D>& grid,
                                            const std::vector<Vec<D>>& pos, std::size_t owned,
                                            const std::function<double(std::size_t)>& reach, const Cells& cells) {
  RankBoxes<D> mine;
  for (std::size_t i = 0; i < owned; ++i) {
    std::array<double, D> x{};
    for (int k = 0; k < D; ++k) x[static_cast<std::size_t>(k)] = pos[i][k];
    mine.particles.include(x, x, std::max(reach(i), 0.0));  // (a radius < 0 would mark the box empty)
  }
  const double edge = grid.lattice.cell_size * grid.block;
  for (const auto& e : cells) {
    const std::array<int, D> t = coord_of_index<D>(grid, static_cast<std::size_t>(e.cell));
    std::array<double, D> lo{}, hi{};
    for (std::size_t k = 0; k < D; ++k) {
      lo[k] = grid.lattice.lo[static_cast<int>(k)] + edge * t[k];
      hi[k] = lo[k] + edge;
    }
    mine.readers.include(lo, hi, e.need);
  }
  const auto values = mine.values();
  return RankBoxes<D>::of_values(comm.gather_values(values));
}

template <int D>
void Halo<D>::build(const Communicator& comm, const Decomposition<D>& grid, Particles<D>& p,
                    const std::function<double(std::size_t)>& need, const std::function<double(std::size_t)>& reach) {
  const auto ranks = static_cast<std::size_t>(comm.size());
  const auto me = static_cast<std::size_t>(comm.rank());
  owned_ = p.size();
  send_.assign(ranks, {});
  // Which other ranks hold particles that read ghosts (need >= 0) in each top cell, with the
  // largest `need` radius of theirs there: each rank lists its own cells and sends the list to the
  // ranks whose particles may come within range of them (list_recipients), so a rank hears from its
  // neighbours only, where a shared bitmap of one bit per rank and cell would grow as P^2. (An
  // inactive particle of a block step pairs with no ghost, so ghosts around it alone would be spare.)
  // Everything below is kept for this rank's own cells and the listed ones only (TopCellSet), never
  // for every top cell of the grid (whose number grows with P).
  std::vector<std::array<int, D>> coord_of(owned_);
  for (std::size_t i = 0; i < owned_; ++i) coord_of[i] = grid.top_coord(p.pos[i]);
  const TopCellSet<D> own(coord_of);
  std::vector<std::uint32_t> own_place(owned_);
  std::vector<double> my_need(own.size(), -1.0), reach_max(own.size(), 0.0);
  for (std::size_t i = 0; i < owned_; ++i) {
    const std::uint32_t k = own_place[i] = own.place(coord_of[i]);
    reach_max[k] = std::max(reach_max[k], reach(i));
    my_need[k] = std::max(my_need[k], need(i));
  }
  struct Reading {
    std::uint64_t cell;
    double need;
  };
  std::vector<Reading> reading;
  for (std::size_t k = 0; k < own.size(); ++k)
    if (my_need[k] >= 0) reading.push_back({grid.top_index(own.coord(k)), my_need[k]});
  std::vector<std::byte> listed(reading.size() * sizeof(Reading));
  if (!reading.empty()) std::memcpy(listed.data(), reading.data(), listed.size());
  std::vector<std::vector<std::byte>> to_ranks(ranks);
  for (const std::size_t r : list_recipients(gather_rank_boxes(comm, grid, p.pos, owned_, reach, reading), me))
    to_ranks[r] = listed;
  const std::vector<std::vector<std::byte>> lists = comm.exchange(to_ranks);
  const auto each_listed = [&](auto&& f) {
    for (std::size_t r = 0; r < ranks; ++r) {
      if (r == me) continue;
      for (std::size_t k = 0; k < lists[r].size() / sizeof(Reading); ++k) {
        Reading e;
        std::memcpy(&e, lists[r].data() + k * sizeof(Reading), sizeof e);
        f(r, coord_of_index<D>(grid, static_cast<std::size_t>(e.cell)), e.need);
      }
    }
  };
  // The listed cells; for the u-th, readers[first[u] .. first[u + 1]): the other ranks reading
  // there with their need, and need_max[u]: the largest.
  std::vector<std::array<int, D>> listed_coords;
  each_listed([&](std::size_t, const std::array<int, D>& t, double) { listed_coords.push_back(t); });
  const TopCellSet<D> others(listed_coords);
  struct Reader {
    std::uint32_t rank;
    double need;
  };
  std::vector<std::uint32_t> first(others.size() + 1, 0);
  std::vector<Reader> readers;
  std::vector<double> need_max(others.size(), 0.0);
  each_listed([&](std::size_t, const std::array<int, D>& t, double r) {
    const std::uint32_t u = others.place(t);
    ++first[u + 1];
    need_max[u] = std::max(need_max[u], r);
  });
  for (std::size_t u = 0; u < others.size(); ++u) first[u + 1] += first[u];
  readers.resize(first.back());
  {
    std::vector<std::uint32_t> next(first.begin(), first.end() - 1);
    each_listed([&](std::size_t r, const std::array<int, D>& t, double need_r) {
      readers[next[others.place(t)]++] = {static_cast<std::uint32_t>(r), need_r};
    });
  }
  const double edge = grid.lattice.cell_size * grid.block;
  // Box-to-box distance below r, from the whole cells between two top cells along each axis?
  auto apart_within = [&](const std::array<int, D>& cells_apart, double r) {
    double gap2 = 0;
    for (int k = 0; k < D; ++k) {
      const double gap = cells_apart[static_cast<std::size_t>(k)] * edge;
      gap2 += gap * gap;
    }
    return gap2 < r * r;
  };
  auto within = [&](const std::array<int, D>& a, const std::array<int, D>& b, double r) {
    std::array<int, D> apart{};
    for (std::size_t k = 0; k < D; ++k) apart[k] = std::max(0, std::abs(a[k] - b[k]) - 1);
    return apart_within(apart, r);
  };
  // Per own cell: the listed cells (by place u) its particles may have to go to, where the box gap
  // is below max(need_max[u], reach_max of the own cell) -- i.e. below the reach (scan around the
  // own cell) or below need_max[u] (scan around the listed one). Each scan spans its own cell's
  // radius, not the widest of all (one particle with a large h would otherwise widen every scan),
  // and cells beyond that radius of the other set's bounding box are not scanned at all.
  std::vector<std::vector<std::uint32_t>> targets(own.size());
  const double margin = 1.0 + 1e-12;
  for (std::size_t k = 0; k < own.size() && others.size() > 0; ++k) {
    const std::array<int, D>& ts = own.coord(k);
    const double R = reach_max[k] * margin;
    if (reach_max[k] <= 0 || !apart_within(others.cells_apart(ts), R)) continue;
    for_each_top_cell_near<D>(grid, ts, static_cast<int>(std::ceil(R / edge)), [&](const std::array<int, D>& tc) {
      const std::uint32_t u = others.place(tc);
      if (u != TopCellSet<D>::kAbsent && within(tc, ts, R)) targets[k].push_back(u);
    });
  }
  for (std::size_t u = 0; u < others.size() && own.size() > 0; ++u) {
    const std::array<int, D>& tc = others.coord(u);
    const double R = need_max[u] * margin;
    if (need_max[u] <= 0 || !apart_within(own.cells_apart(tc), R)) continue;
    for_each_top_cell_near<D>(grid, tc, static_cast<int>(std::ceil(R / edge)), [&](const std::array<int, D>& ts) {
      const std::uint32_t k = own.place(ts);
      if (k != TopCellSet<D>::kAbsent && within(tc, ts, R)) targets[k].push_back(static_cast<std::uint32_t>(u));
    });
  }
  for (auto& t : targets) {
    std::sort(t.begin(), t.end());
    t.erase(std::unique(t.begin(), t.end()), t.end());
  }
  std::vector<std::size_t> to;
  for (std::size_t j = 0; j < owned_; ++j) {
    to.clear();
    const double reach_j = reach(j);
    for (const std::uint32_t u : targets[own_place[j]]) {
      // 1e-12 margin: the box distance and the pair distance round differently; a spare ghost is
      // harmless. Each reader by its own need there, so that which lists arrived changes nothing.
      const double d2 = grid.distance2_to(p.pos[j], others.coord(u));
      const double R_max = std::max(need_max[u], reach_j) * (1.0 + 1e-12);
      if (d2 >= R_max * R_max) continue;
      for (std::uint32_t k = first[u]; k < first[u + 1]; ++k) {
        const double R = std::max(readers[k].need, reach_j) * (1.0 + 1e-12);
        if (d2 < R * R && std::find(to.begin(), to.end(), readers[k].rank) == to.end()) to.push_back(readers[k].rank);
      }
    }
    for (const std::size_t r : to) send_[r].push_back(static_cast<std::uint32_t>(j));
  }
  std::vector<std::vector<std::byte>> send(ranks);
  for (std::size_t r = 0; r < ranks; ++r)
    if (!send_[r].empty()) send[r] = pack(p, send_[r], {});
  unpack_all(p, comm.exchange(send));
  ghosts_ = p.size() - owned_;
}

template <int D>
void Halo<D>::refresh(const Communicator& comm, Particles<D>& p, unsigned halo_flag) const {
  FieldNames fields;
  p.for_each_field([&](const FieldInfo& info, const auto&) {
    if (info.flags & halo_flag) fields.push_back(info.name);
  });
  const auto ranks = static_cast<std::size_t>(comm.size());
  std::vector<std::vector<std::byte>> send(ranks);
  for (std::size_t r = 0; r < ranks; ++r)
    if (!send_[r].empty()) send[r] = pack(p, send_[r], fields);
  const auto recv = comm.exchange(send);
  std::size_t first = owned_;
  for (const auto& buf : recv) {  // same ranks, same order as build(): the same ghost slots
    unpack(p, first, buf, fields);
    first += packed_count(buf);
  }
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
template class Halo<2>;
template class Halo<3>;

}  // namespace sphdisk
