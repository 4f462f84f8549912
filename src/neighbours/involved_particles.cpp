#include "neighbours/involved_particles.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "neighbours/cell_grid.hpp"
#include "parallel/loops.hpp"

namespace sphdisk {

namespace {

// Summed-volume tables over a coarse grid of cells: table[c] (c in 0 .. dims per axis, inclusive)
// holds the sum of the per-cell values of the cells below c along every axis, so that any box of
// cells is summed from its 2^D corners, and a box added to every cell of it is four (eight) updates
// of a difference table before the sums.
// floor(t) as an integer for |t| < 1e15 (x86-64's baseline has no rounding instruction: std::floor
// is a call, cell_grid.hpp).
inline std::int64_t floor_to_int(double t) {
  const auto i = static_cast<std::int64_t>(t);
  return i - static_cast<std::int64_t>(static_cast<double>(i) > t);
}

template <int D>
struct CoarseGrid {
  Vec<D> lo;
  double cell = 0, inv_cell = 0;
  std::array<std::size_t, D> dims{};  // cells per axis

  std::size_t table_size() const {
    std::size_t size = 1;
    for (std::size_t k = 0; k < D; ++k) size *= dims[k] + 1;
    return size;
  }
  std::size_t at(const std::array<std::size_t, D>& c) const {
    std::size_t idx = 0;
    for (int k = D - 1; k >= 0; --k) idx = idx * (dims[static_cast<std::size_t>(k)] + 1) + c[static_cast<std::size_t>(k)];
    return idx;
  }
  // The cells of the box x +- reach clipped to the grid, [first, last) per axis; false if none.
  // The margin of 1e-6 cells covers the round-off of the quotients (cell coordinates stay below
  // ~1e7: the grid has a bounded number of cells).
  bool box(const Vec<D>& x, double reach, std::array<std::size_t, D>& first, std::array<std::size_t, D>& last) const {
    for (int k = 0; k < D; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      const double extent = static_cast<double>(dims[kk]);
      const double a = (x[k] - reach - lo[k]) * inv_cell - 1e-6, b = (x[k] + reach - lo[k]) * inv_cell + 1e-6;
      if (!(b >= 0.0) || !(a < extent)) return false;  // beyond the grid (or NaN)
      first[kk] = static_cast<std::size_t>(std::max<std::int64_t>(floor_to_int(std::max(a, -1.0)), 0));
      last[kk] = static_cast<std::size_t>(std::min<std::int64_t>(floor_to_int(std::min(b, extent)), static_cast<std::int64_t>(dims[kk]) - 1)) + 1;
    }
    return true;
  }
  // Calls f(corner, highs) for the 2^D corners of the box [first, last), highs: how many of its
  // coordinates are upper bounds. A box added to a difference table takes corner with the sign
  // (-1)^highs, a box sum from a summed-volume table takes it with (-1)^(D - highs).
  template <class F>
  static void corners(const std::array<std::size_t, D>& first, const std::array<std::size_t, D>& last, F&& f) {
    for (unsigned corner = 0; corner < (1u << D); ++corner) {
      std::array<std::size_t, D> c;
      int lows = 0;
      for (std::size_t k = 0; k < D; ++k) {
        const bool low = ((corner >> k) & 1u) != 0;
        c[k] = low ? first[k] : last[k];
        lows += low ? 1 : 0;
      }
      f(c, static_cast<int>(D) - lows);
    }
  }
  // Prefix sums along each axis in turn (a difference table becomes per-cell values shifted by one
  // cell per axis; a per-cell table becomes a summed-volume table).
  void prefix_sums(std::vector<std::int32_t>& table) const {
    const std::size_t size = table.size();
    std::size_t stride = 1;
    for (std::size_t axis = 0; axis < D; ++axis) {
      const std::size_t len = dims[axis] + 1;
      for (std::size_t idx = 0; idx < size; ++idx)
        if ((idx / stride) % len != 0) table[idx] += table[idx - stride];
      stride *= len;
    }
  }
};

}  // namespace

template <int D>
void involved_particles(const std::vector<Vec<D>>& pos, const std::vector<double>& h, std::size_t active,
                        const std::vector<double>& radius, std::vector<std::uint32_t>& members) {
  const std::size_t n = pos.size();
  active = std::min(active, n);
  if (radius.size() < active) throw std::logic_error("involved_particles: one radius per active particle");
  members.resize(active);
  std::iota(members.begin(), members.end(), 0u);
  if (active == 0) return;
  // The grid spans the active particles' reach; its cells are the median radius, larger where they
  // would be too many (a few per active particle at most: the tables stay small, the tests only
  // less sharp).
  CoarseGrid<D> g;
  Vec<D> hi;
  for (int k = 0; k < D; ++k) {
    g.lo[k] = std::numeric_limits<double>::infinity();
    hi[k] = -std::numeric_limits<double>::infinity();
  }
  for (std::size_t i = 0; i < active; ++i) {
    if (!(radius[i] > 0) || !std::isfinite(radius[i])) {  // no bound to the reach: every particle
      members.resize(n);
      std::iota(members.begin(), members.end(), 0u);
      return;
    }
    for (int k = 0; k < D; ++k) {
      g.lo[k] = std::min(g.lo[k], pos[i][k] - radius[i]);
      hi[k] = std::max(hi[k], pos[i][k] + radius[i]);
    }
  }
  {
    std::vector<double> sorted(radius.begin(), radius.begin() + static_cast<std::ptrdiff_t>(active));
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(active / 2), sorted.end());
    // make_lattice grows the cells until there are at most max(4 x its count, 1024): here
    // max(8 x active, 16384).
    const Lattice<D> lattice = make_lattice(g.lo, hi, std::max<std::size_t>(2 * active, 4096), sorted[active / 2]);
    g.cell = lattice.cell_size;
    for (std::size_t k = 0; k < D; ++k) g.dims[k] = static_cast<std::size_t>(lattice.dims[k]);
  }
  g.inv_cell = 1.0 / g.cell;
  // reached: the cells within some active particle's radius (a difference table of the boxes, then
  // summed); count: the active particles per cell as a summed-volume table.
  std::vector<std::int32_t> reached(g.table_size(), 0), count(g.table_size(), 0);
  for (std::size_t i = 0; i < active; ++i) {
    std::array<std::size_t, D> first{}, last{};
    if (g.box(pos[i], radius[i], first, last))
      CoarseGrid<D>::corners(first, last, [&](const std::array<std::size_t, D>& c, int highs) {
        reached[g.at(c)] += highs % 2 == 0 ? 1 : -1;
      });
    g.box(pos[i], 0.0, first, last);  // its own cell
    std::array<std::size_t, D> above;
    for (std::size_t k = 0; k < D; ++k) above[k] = first[k] + 1;
    ++count[g.at(above)];
  }
  g.prefix_sums(reached);  // reached[c]: the boxes covering cell c (entries at index 0 per axis unused)
  g.prefix_sums(count);
  std::vector<unsigned char> involved(n - active);
  par::for_each(n - active, [&](std::size_t k) {
    const Vec<D>& x = pos[active + k];
    std::array<std::size_t, D> first, last;
    bool yes = false;
    if (g.box(x, 0.0, first, last)) yes = reached[g.at(first)] != 0;  // within an active particle's radius
    if (!yes && g.box(x, 2.0 * h[active + k], first, last)) {          // an active particle within its support
      std::int64_t sum = 0;
      CoarseGrid<D>::corners(first, last, [&](const std::array<std::size_t, D>& c, int highs) {
        sum += (D - highs) % 2 == 0 ? count[g.at(c)] : -count[g.at(c)];
      });
      yes = sum != 0;
    }
    involved[k] = yes ? 1 : 0;
  });
  for (std::size_t k = 0; k < n - active; ++k)
    if (involved[k]) members.push_back(static_cast<std::uint32_t>(active + k));
}

template void involved_particles(const std::vector<Vec<2>>&, const std::vector<double>&, std::size_t,
                                 const std::vector<double>&, std::vector<std::uint32_t>&);
template void involved_particles(const std::vector<Vec<3>>&, const std::vector<double>&, std::size_t,
                                 const std::vector<double>&, std::vector<std::uint32_t>&);

}  // namespace sphdisk
