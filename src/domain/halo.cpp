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

}  // namespace

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
  // Scans around each cell a of `from` by radius[a] for the cells b of `to` (not at all where to's
  // box lies beyond it), calling found(a, b) for each within it.
  auto scan = [&](const TopCellSet<D>& from, const std::vector<double>& radius, const TopCellSet<D>& to, auto&& found) {
    for (std::size_t a = 0; a < from.size() && to.size() > 0; ++a) {
      const std::array<int, D>& ta = from.coord(a);
      const double R = radius[a] * margin;
      if (radius[a] <= 0 || !apart_within(to.cells_apart(ta), R)) continue;
      for_each_top_cell_near<D>(grid, ta, static_cast<int>(std::ceil(R / edge)), [&](const std::array<int, D>& tb) {
        const std::uint32_t b = to.place(tb);
        if (b != TopCellSet<D>::kAbsent && within(ta, tb, R)) found(a, b);
      });
    }
  };
  scan(own, reach_max, others, [&](std::size_t k, std::uint32_t u) { targets[k].push_back(u); });
  scan(others, need_max, own, [&](std::size_t u, std::uint32_t k) { targets[k].push_back(static_cast<std::uint32_t>(u)); });
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
