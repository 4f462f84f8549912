#include "domain/halo.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include "domain/particle_packing.hpp"
#include "domain/rank_boxes.hpp"
#include "domain/top_cell_set.hpp"

namespace sphdisk {

using namespace packing;

namespace {

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

// The names of p's fields whose flags pass `keep`.
template <int D, class Keep>
FieldNames fields_where(const Particles<D>& p, Keep keep) {
  FieldNames fields;
  p.for_each_field([&](const FieldInfo& info, const auto&) {
    if (keep(info.flags)) fields.push_back(info.name);
  });
  return fields;
}

// This rank's top cells: each owned particle's place among them, and per cell the largest need
// (-1 where no particle reads ghosts) and the largest reach of its particles.
template <int D>
struct OwnCells {
  TopCellSet<D> set;
  std::vector<std::uint32_t> place_of;  // per owned particle
  std::vector<double> need, reach;      // per cell
};

template <int D>
OwnCells<D> own_cells_of(const Decomposition<D>& grid, const std::vector<Vec<D>>& pos, std::size_t owned,
                         const std::function<double(std::size_t)>& need, const std::function<double(std::size_t)>& reach) {
  std::vector<std::array<int, D>> coord_of(owned);
  for (std::size_t i = 0; i < owned; ++i) coord_of[i] = grid.top_coord(pos[i]);
  OwnCells<D> own{TopCellSet<D>(coord_of), std::vector<std::uint32_t>(owned), {}, {}};
  own.need.assign(own.set.size(), -1.0);
  own.reach.assign(own.set.size(), 0.0);
  for (std::size_t i = 0; i < owned; ++i) {
    const std::uint32_t k = own.place_of[i] = own.set.place(coord_of[i]);
    own.reach[k] = std::max(own.reach[k], reach(i));
    own.need[k] = std::max(own.need[k], need(i));
  }
  return own;
}

// A top cell in which a rank has particles that read ghosts, with their largest need there: what
// the reading lists carry.
struct Reading {
  std::uint64_t cell;
  double need;
};

// Another rank's reading cell, as received.
template <int D>
struct ListedReading {
  std::uint32_t rank;
  std::array<int, D> cell;
  double need;
};

// This rank's boxes (domain/rank_boxes.hpp), gathered from all ranks: its particles with their
// largest reach, its reading cells as distance2_to bounds them.
template <int D>
std::vector<RankBoxes<D>> gather_rank_boxes(const Communicator& comm, const Decomposition<D>& grid,
                                            const std::vector<Vec<D>>& pos, std::size_t owned,
                                            const std::function<double(std::size_t)>& reach,
                                            const std::vector<Reading>& cells) {
  RankBoxes<D> mine;
  for (std::size_t i = 0; i < owned; ++i) {
    std::array<double, D> x{};
    for (int k = 0; k < D; ++k) x[static_cast<std::size_t>(k)] = pos[i][k];
    mine.particles.include(x, x, std::max(reach(i), 0.0));  // (a radius < 0 would mark the box empty)
  }
  const double edge = grid.lattice.cell_size * grid.block;
  for (const Reading& e : cells) {
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

// Sends this rank's reading cells to the ranks whose particles may come within range of them
// (list_recipients), so a rank hears from its neighbours only, where a shared bitmap of one bit per
// rank and cell would grow as P^2; returns the lists received, in rank order. (An inactive particle
// of a block step pairs with no ghost, so ghosts around it alone would be spare.)
template <int D>
std::vector<ListedReading<D>> exchange_reading_lists(const Communicator& comm, const Decomposition<D>& grid,
                                                     const std::vector<Vec<D>>& pos, std::size_t owned,
                                                     const std::function<double(std::size_t)>& reach,
                                                     const OwnCells<D>& own) {
  std::vector<Reading> reading;
  for (std::size_t k = 0; k < own.set.size(); ++k)
    if (own.need[k] >= 0) reading.push_back({grid.top_index(own.set.coord(k)), own.need[k]});
  std::vector<std::byte> listed(reading.size() * sizeof(Reading));
  if (!reading.empty()) std::memcpy(listed.data(), reading.data(), listed.size());
  const auto me = static_cast<std::size_t>(comm.rank());
  std::vector<std::vector<std::byte>> to_ranks(static_cast<std::size_t>(comm.size()));
  for (const std::size_t r : list_recipients(gather_rank_boxes(comm, grid, pos, owned, reach, reading), me))
    to_ranks[r] = listed;
  const std::vector<std::vector<std::byte>> lists = comm.exchange(to_ranks);
  std::vector<ListedReading<D>> received;
  for (std::size_t r = 0; r < lists.size(); ++r) {
    if (r == me) continue;
    for (std::size_t k = 0; k < lists[r].size() / sizeof(Reading); ++k) {
      Reading e;
      std::memcpy(&e, lists[r].data() + k * sizeof(Reading), sizeof e);
      received.push_back({static_cast<std::uint32_t>(r), coord_of_index<D>(grid, static_cast<std::size_t>(e.cell)), e.need});
    }
  }
  return received;
}

// The cells other ranks listed: for the u-th (its place in `set`), the ranks reading there with
// their need, readers[first[u] .. first[u + 1]), and need_max[u], the largest.
template <int D>
struct ListedCells {
  struct Reader {
    std::uint32_t rank;
    double need;
  };
  TopCellSet<D> set;
  std::vector<std::uint32_t> first;
  std::vector<Reader> readers;
  std::vector<double> need_max;

  explicit ListedCells(const std::vector<ListedReading<D>>& listed) {
    std::vector<std::array<int, D>> coords;
    for (const auto& e : listed) coords.push_back(e.cell);
    set = TopCellSet<D>(coords);
    first.assign(set.size() + 1, 0);
    need_max.assign(set.size(), 0.0);
    for (const auto& e : listed) {
      const std::uint32_t u = set.place(e.cell);
      ++first[u + 1];
      need_max[u] = std::max(need_max[u], e.need);
    }
    for (std::size_t u = 0; u < set.size(); ++u) first[u + 1] += first[u];
    readers.resize(first.back());
    std::vector<std::uint32_t> next(first.begin(), first.end() - 1);
    for (const auto& e : listed) readers[next[set.place(e.cell)]++] = {e.rank, e.need};
  }
};

// Whether two top cells lie within r of each other, from the whole cells between them along each
// axis (the box-to-box distance).
template <int D>
bool cells_apart_within(const Decomposition<D>& grid, const std::array<int, D>& cells_apart, double r) {
  const double edge = grid.lattice.cell_size * grid.block;
  double gap2 = 0;
  for (int k = 0; k < D; ++k) {
    const double gap = cells_apart[static_cast<std::size_t>(k)] * edge;
    gap2 += gap * gap;
  }
  return gap2 < r * r;
}

// Per own cell: the listed cells (by place) its particles may have to go to, where the box gap is
// below max(need_max of the listed cell, reach of the own cell) -- i.e. below the reach (scan around
// the own cell) or below the need (scan around the listed one). Each scan spans its own cell's
// radius, not the widest of all (one particle with a large h would otherwise widen every scan), and
// cells beyond that radius of the other set's bounding box are not scanned at all.
template <int D>
std::vector<std::vector<std::uint32_t>> target_cells(const Decomposition<D>& grid, const OwnCells<D>& own,
                                                     const ListedCells<D>& listed) {
  const double edge = grid.lattice.cell_size * grid.block;
  const auto within = [&](const std::array<int, D>& a, const std::array<int, D>& b, double r) {
    std::array<int, D> apart{};
    for (std::size_t k = 0; k < D; ++k) apart[k] = std::max(0, std::abs(a[k] - b[k]) - 1);
    return cells_apart_within<D>(grid, apart, r);
  };
  const double margin = 1.0 + 1e-12;
  // Scans around each cell a of `from` by radius[a] for the cells b of `to`, calling found(a, b)
  // for each within it.
  const auto scan = [&](const TopCellSet<D>& from, const std::vector<double>& radius, const TopCellSet<D>& to, auto&& found) {
    for (std::size_t a = 0; a < from.size() && to.size() > 0; ++a) {
      const std::array<int, D>& ta = from.coord(a);
      const double R = radius[a] * margin;
      if (radius[a] <= 0 || !cells_apart_within<D>(grid, to.cells_apart(ta), R)) continue;
      for_each_top_cell_near<D>(grid, ta, static_cast<int>(std::ceil(R / edge)), [&](const std::array<int, D>& tb) {
        const std::uint32_t b = to.place(tb);
        if (b != TopCellSet<D>::kAbsent && within(ta, tb, R)) found(a, b);
      });
    }
  };
  std::vector<std::vector<std::uint32_t>> targets(own.set.size());
  scan(own.set, own.reach, listed.set, [&](std::size_t k, std::uint32_t u) { targets[k].push_back(u); });
  scan(listed.set, listed.need_max, own.set, [&](std::size_t u, std::uint32_t k) { targets[k].push_back(static_cast<std::uint32_t>(u)); });
  for (auto& t : targets) {
    std::sort(t.begin(), t.end());
    t.erase(std::unique(t.begin(), t.end()), t.end());
  }
  return targets;
}

}  // namespace

// Each rank lists the top cells where its particles read ghosts and sends the list to the ranks
// within reach; each owner then sends a particle to every listed reader within the reader's need
// or the particle's reach. Everything is kept for this rank's own cells and the listed ones only
// (TopCellSet), never for every top cell of the grid (whose number grows with P).
template <int D>
void Halo<D>::build(const Communicator& comm, const Decomposition<D>& grid, Particles<D>& p,
                    const std::function<double(std::size_t)>& need, const std::function<double(std::size_t)>& reach) {
  const auto ranks = static_cast<std::size_t>(comm.size());
  owned_ = p.size();
  const OwnCells<D> own = own_cells_of(grid, p.pos, owned_, need, reach);
  const ListedCells<D> listed(exchange_reading_lists(comm, grid, p.pos, owned_, reach, own));
  const std::vector<std::vector<std::uint32_t>> targets = target_cells(grid, own, listed);
  send_.assign(ranks, {});
  std::vector<std::size_t> to;
  for (std::size_t j = 0; j < owned_; ++j) {
    to.clear();
    const double reach_j = reach(j);
    for (const std::uint32_t u : targets[own.place_of[j]]) {
      // 1e-12 margin: the box distance and the pair distance round differently; a spare ghost is
      // harmless. Each reader by its own need there, so that which lists arrived changes nothing.
      const double d2 = grid.distance2_to(p.pos[j], listed.set.coord(u));
      const double R_max = std::max(listed.need_max[u], reach_j) * (1.0 + 1e-12);
      if (d2 >= R_max * R_max) continue;
      for (std::uint32_t k = listed.first[u]; k < listed.first[u + 1]; ++k) {
        const double R = std::max(listed.readers[k].need, reach_j) * (1.0 + 1e-12);
        const std::uint32_t r = listed.readers[k].rank;
        if (d2 < R * R && std::find(to.begin(), to.end(), r) == to.end()) to.push_back(r);
      }
    }
    for (const std::size_t r : to) send_[r].push_back(static_cast<std::uint32_t>(j));
  }
  // Without the fields that the density and stress refreshes bring before any pair loop reads them,
  // nor those only a particle's owner reads.
  const FieldNames fields =
      fields_where(p, [](unsigned flags) { return !(flags & (kHaloDensity | kHaloStress | kOwnerOnly)); });
  std::vector<std::vector<std::byte>> send(ranks);
  for (std::size_t r = 0; r < ranks; ++r)
    if (!send_[r].empty()) send[r] = pack(p, send_[r], fields);
  unpack_all(p, comm.exchange(send), fields);
  ghosts_ = p.size() - owned_;
}

template <int D>
void Halo<D>::refresh(const Communicator& comm, Particles<D>& p, unsigned halo_flag) const {
  const FieldNames fields = fields_where(p, [halo_flag](unsigned flags) { return (flags & halo_flag) != 0; });
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

template class Halo<2>;
template class Halo<3>;

}  // namespace sphdisk
