#include "neighbours/cell_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "core/overwrite_vector.hpp"
#include "parallel/loops.hpp"

namespace sphdisk {

template <int D>
std::size_t CellGrid<D>::cell_of(const Vec<D>& x) const {
  std::array<int, D> c;
  for (int k = 0; k < D; ++k) c[static_cast<std::size_t>(k)] = coord(x[k], k);
  return linear(c);
}

template <int D>
void bounding_box(const std::vector<Vec<D>>& pos, Vec<D>& lo, Vec<D>& hi) {
  struct Box {
    Vec<D> lo, hi;
  };
  Box init;
  for (int k = 0; k < D; ++k) {
    init.lo[k] = std::numeric_limits<double>::max();
    init.hi[k] = std::numeric_limits<double>::lowest();
  }
  const Box b = par::reduce(
      pos.size(), init, [&](std::size_t i) { return Box{pos[i], pos[i]}; },
      [](const Box& a, const Box& c) {
        Box r;
        for (int k = 0; k < D; ++k) {
          r.lo[k] = std::min(a.lo[k], c.lo[k]);
          r.hi[k] = std::max(a.hi[k], c.hi[k]);
        }
        return r;
      });
  lo = b.lo;
  hi = b.hi;
}

namespace {

// The grid of the lattice cells spanned by [lo, hi], the bounding box of pos.
template <int D>
void fill_cell_grid(const Lattice<D>& lattice, const Vec<D>& lo, const Vec<D>& hi, const std::vector<Vec<D>>& pos,
                    const std::vector<std::uint64_t>& id, CellGrid<D>& g) {
  const std::size_t n = pos.size();
  g.lo = lattice.lo;
  g.cell_size = lattice.cell_size;
  if (n == 0) {
    g.origin.fill(0);
    g.dims.fill(1);
    g.offsets.assign(2, 0);
    g.sorted.clear();
    g.sorted_pos.clear();
    return;
  }
  // This grid spans the lattice cells of the particles' bounding box (all of the lattice when pos
  // holds every particle).
  g.origin.fill(0);
  g.dims = lattice.dims;
  for (int k = 0; k < D; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    const int first = g.coord(lo[k], k), last = g.coord(hi[k], k);
    g.origin[kk] = first;
    g.dims[kk] = last - first + 1;
  }

  std::size_t ncells = 1;
  for (int d : g.dims) ncells *= static_cast<std::size_t>(d);

  // Counting sort: keys in parallel, histogram and stable scatter serially (O(N), as in P98).
  auto& key = g.key;
  key.resize(n);
  par::for_each(n, [&](std::size_t i) { key[i] = static_cast<std::uint32_t>(g.cell_of(pos[i])); });
  g.offsets.assign(ncells + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ++g.offsets[key[i] + 1];
  for (std::size_t c = 0; c < ncells; ++c) g.offsets[c + 1] += g.offsets[c];
  g.sorted.resize(n);
  {
    // (An OverwriteVector: a copy of one entry per cell made every evaluation lies on huge pages.)
    OverwriteVector<std::uint32_t> fill(g.offsets.begin(), g.offsets.end() - 1);
    for (std::size_t i = 0; i < n; ++i) g.sorted[fill[key[i]]++] = static_cast<std::uint32_t>(i);
  }
  // Order inside each cell by x, then by particle ID (cells hold a handful of particles: insertion
  // sort). Cells of a row follow each other in x, so every row of cells is sorted by x; particles
  // reordered in this order (the runs' periodic reorder) lie closer in memory to their neighbours
  // than in ID order inside cells (cell_grid.hpp).
  const auto before = [&](std::uint32_t a, std::uint32_t b) {
    return pos[a][0] < pos[b][0] || (pos[a][0] == pos[b][0] && id[a] < id[b]);
  };
  par::for_each(ncells, [&](std::size_t c) {
    auto* first = g.sorted.data() + g.offsets[c];
    auto* last = g.sorted.data() + g.offsets[c + 1];
    for (auto* p = first + 1; p < last; ++p) {
      const std::uint32_t v = *p;
      auto* q = p;
      while (q > first && before(v, *(q - 1))) {
        *q = *(q - 1);
        --q;
      }
      *q = v;
    }
  });
  g.sorted_pos.resize(n);
  par::for_each(n, [&](std::size_t k) { g.sorted_pos[k] = pos[g.sorted[k]]; });
}

}  // namespace

template <int D>
Lattice<D> make_lattice(const Vec<D>& lo, const Vec<D>& hi, std::size_t n, double min_cell_size) {
  // A non-finite extent would grow the cell size below for ever: say what is wrong instead.
  for (int k = 0; k < D; ++k)
    if (!std::isfinite(hi[k] - lo[k]))
      throw NumericalError("a particle position is not finite, so no cell grid can be built; reduce the timestep "
                           "factors or check the set-up");
  Lattice<D> L;
  L.lo = lo;
  const double max_cells = std::max<double>(4.0 * static_cast<double>(n), 1024.0);
  L.cell_size = min_cell_size;
  if (!(L.cell_size > 0)) {  // no lower bound (or a zero h): the cap on cells sets the size
    double extent = 0;
    for (int k = 0; k < D; ++k) extent = std::max(extent, hi[k] - lo[k]);
    L.cell_size = std::max(extent * 1e-9, std::numeric_limits<double>::min());
  }
  for (;;) {
    double ncells = 1;
    for (int k = 0; k < D; ++k) ncells *= std::floor((hi[k] - lo[k]) / L.cell_size) + 1.0;
    if (ncells <= max_cells) break;
    L.cell_size *= 1.25;
  }
  for (int k = 0; k < D; ++k)
    L.dims[static_cast<std::size_t>(k)] = static_cast<int>(std::floor((hi[k] - lo[k]) / L.cell_size)) + 1;
  return L;
}

template <int D>
void build_cell_grid(const std::vector<Vec<D>>& pos, const std::vector<std::uint64_t>& id, double min_cell_size,
                     CellGrid<D>& g) {
  if (pos.empty()) {
    build_cell_grid(Lattice<D>{Vec<D>{}, min_cell_size, {}}, pos, id, g);
    return;
  }
  Vec<D> lo, hi;
  bounding_box(pos, lo, hi);
  fill_cell_grid(make_lattice(lo, hi, pos.size(), min_cell_size), lo, hi, pos, id, g);
}

template <int D>
void build_cell_grid(const Lattice<D>& lattice, const std::vector<Vec<D>>& pos, const std::vector<std::uint64_t>& id,
                     CellGrid<D>& g) {
  Vec<D> lo, hi;
  if (!pos.empty()) bounding_box(pos, lo, hi);
  fill_cell_grid(lattice, lo, hi, pos, id, g);
}
template <int D>
void renumber_particles(CellGrid<D>& g, std::span<const std::uint32_t> moved) {
  if (moved.empty()) return;
  OverwriteVector<std::uint32_t> now(moved.size());
  par::for_each(moved.size(), [&](std::size_t k) { now[moved[k]] = static_cast<std::uint32_t>(k); });
  par::for_each(g.sorted.size(), [&](std::size_t s) {
    if (g.sorted[s] < moved.size()) g.sorted[s] = now[g.sorted[s]];
  }, {}, 4096);
}

template struct CellGrid<2>;
template struct CellGrid<3>;
template Lattice<2> make_lattice(const Vec<2>&, const Vec<2>&, std::size_t, double);
template Lattice<3> make_lattice(const Vec<3>&, const Vec<3>&, std::size_t, double);
template void build_cell_grid(const Lattice<2>&, const std::vector<Vec<2>>&, const std::vector<std::uint64_t>&, CellGrid<2>&);
template void build_cell_grid(const Lattice<3>&, const std::vector<Vec<3>>&, const std::vector<std::uint64_t>&, CellGrid<3>&);
template void build_cell_grid(const std::vector<Vec<2>>&, const std::vector<std::uint64_t>&, double, CellGrid<2>&);
template void build_cell_grid(const std::vector<Vec<3>>&, const std::vector<std::uint64_t>&, double, CellGrid<3>&);
template void bounding_box(const std::vector<Vec<2>>&, Vec<2>&, Vec<2>&);
template void bounding_box(const std::vector<Vec<3>>&, Vec<3>&, Vec<3>&);
template void renumber_particles(CellGrid<2>&, std::span<const std::uint32_t>);
template void renumber_particles(CellGrid<3>&, std::span<const std::uint32_t>);

}  // namespace sphdisk
