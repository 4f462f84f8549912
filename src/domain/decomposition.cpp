#include "domain/decomposition.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace sphdisk {

template <int D>
std::array<int, D> Decomposition<D>::top_coord(const Vec<D>& x) const {
  std::array<int, D> t;
  for (int k = 0; k < D; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    // The lattice cell first (as CellGrid::coord computes it), then its top cell: a particle's fine
    // cell lies wholly inside one top cell.
    const double c = std::floor((x[k] - lattice.lo[k]) / lattice.cell_size);
    const int fine = !(c >= 0) ? 0 : (c >= lattice.dims[kk] ? lattice.dims[kk] - 1 : static_cast<int>(c));
    t[kk] = std::min(fine / block, top_dims[kk] - 1);
  }
  return t;
}

template <int D>
std::size_t Decomposition<D>::top_index(const std::array<int, D>& t) const {
  std::size_t idx = 0;
  for (int k = D - 1; k >= 0; --k)
    idx = idx * static_cast<std::size_t>(top_dims[static_cast<std::size_t>(k)]) + static_cast<std::size_t>(t[static_cast<std::size_t>(k)]);
  return idx;
}

template <int D>
double Decomposition<D>::distance2_to(const Vec<D>& x, const std::array<int, D>& t) const {
  const double edge = lattice.cell_size * block;
  double d2 = 0;
  for (int k = 0; k < D; ++k) {
    const double lo = lattice.lo[k] + edge * t[static_cast<std::size_t>(k)];
    const double hi = lo + edge;
    const double d = x[k] < lo ? lo - x[k] : (x[k] > hi ? x[k] - hi : 0.0);
    d2 += d * d;
  }
  return d2;
}

template <int D>
Decomposition<D> make_top_grid(const Lattice<D>& lattice, std::size_t target_cells) {
  Decomposition<D> d;
  d.lattice = lattice;
  double fine = 1;
  for (int n : lattice.dims) fine *= n;
  d.block = std::max(1, static_cast<int>(std::ceil(std::pow(fine / static_cast<double>(std::max<std::size_t>(target_cells, 1)), 1.0 / D))));
  std::size_t cells = 1;
  for (int k = 0; k < D; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    d.top_dims[kk] = (lattice.dims[kk] + d.block - 1) / d.block;
    cells *= static_cast<std::size_t>(d.top_dims[kk]);
  }
  d.owner.assign(cells, 0);
  return d;
}

template <int D>
std::uint64_t morton_key(const std::array<int, D>& t) {
  std::uint64_t key = 0;
  for (int bit = 0; bit < 64 / D; ++bit)
    for (int k = 0; k < D; ++k)
      key |= static_cast<std::uint64_t>((static_cast<unsigned>(t[static_cast<std::size_t>(k)]) >> bit) & 1u)
             << (bit * D + k);
  return key;
}

template <int D>
void assign_owners(Decomposition<D>& d, const std::vector<std::uint64_t>& weights, int ranks) {
  const std::size_t n = d.top_cells();
  std::vector<std::uint64_t> key(n);
  std::array<int, D> t{};
  for (std::size_t c = 0; c < n; ++c) {
    std::size_t rest = c;
    for (int k = 0; k < D; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      t[kk] = static_cast<int>(rest % static_cast<std::size_t>(d.top_dims[kk]));
      rest /= static_cast<std::size_t>(d.top_dims[kk]);
    }
    key[c] = morton_key<D>(t);
  }
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key[a] < key[b]; });
  const std::uint64_t total = std::accumulate(weights.begin(), weights.end(), std::uint64_t{0});
  // A cell goes to the rank whose share of the curve holds the cell's midpoint weight.
  std::uint64_t before = 0;
  for (const std::size_t c : order) {
    const double mid = static_cast<double>(before) + 0.5 * static_cast<double>(weights[c]);
    const int r = total == 0 ? 0 : static_cast<int>(mid * ranks / static_cast<double>(total));
    d.owner[c] = std::clamp(r, 0, ranks - 1);
    before += weights[c];
  }
}

template struct Decomposition<2>;
template struct Decomposition<3>;
template Decomposition<2> make_top_grid(const Lattice<2>&, std::size_t);
template Decomposition<3> make_top_grid(const Lattice<3>&, std::size_t);
template std::uint64_t morton_key<2>(const std::array<int, 2>&);
template std::uint64_t morton_key<3>(const std::array<int, 3>&);
template void assign_owners(Decomposition<2>&, const std::vector<std::uint64_t>&, int);
template void assign_owners(Decomposition<3>&, const std::vector<std::uint64_t>&, int);

}  // namespace sphdisk
