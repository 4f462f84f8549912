#include "app/smoothing_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "neighbours/cell_grid.hpp"
#include "neighbours/neighbour_lists.hpp"

namespace sphdisk {

template <int D>
double calibrate_smoothing_length(Particles<D>& p, double target, ParticleDomain<D>* domain) {
  const std::size_t owned = p.size();
  double volume = 1.0;
  for (int k = 0; k < D; ++k) {  // of the bounding box of all particles (exact min and max)
    double lo = std::numeric_limits<double>::max(), hi = std::numeric_limits<double>::lowest();
    for (const Vec<D>& x : p.pos) lo = std::min(lo, x[k]), hi = std::max(hi, x[k]);
    if (domain) lo = domain->min(lo), hi = domain->max(hi);
    volume *= std::max(hi - lo, 1e-300);
  }
  const std::uint64_t n = domain ? domain->sum(owned) : owned;
  // Start from a uniform distribution over the bounding box: N (2h)^D ~ target volume.
  double h = 0.5 * std::pow(target * volume / static_cast<double>(std::max<std::uint64_t>(n, 1)), 1.0 / D);
  CellGrid<D> grid;
  std::vector<std::uint32_t> counts;
  std::vector<double> support;
  for (int iter = 0; iter < 60; ++iter) {
    if (domain) {
      const double reach = 2.0 * h;
      const auto radius = [reach](std::size_t) { return reach; };
      build_cell_grid(domain->add_ghosts(p, h, radius, radius), p.pos, p.id, grid);
    } else {
      build_cell_grid(p.pos, p.id, h, grid);
    }
    // The neighbours within 2h counted, not listed: a first guess far too large (a bounding box
    // mostly empty, as around a ring or a thin disc) would list thousands per particle.
    counts.assign(owned, 0);
    support.assign(p.pos.size(), 2.0 * h);
    settle_without_lists<D>(grid, p.pos, support, [&counts](std::size_t i, std::span<const std::uint32_t> js, std::span<const double>, double r) {
      counts[i] = static_cast<std::uint32_t>(js.size());
      return r;
    }, owned);
    if (domain) domain->remove_ghosts(p);
    std::uint64_t listed = 0;
    for (std::uint32_t c : counts) listed += c;
    const std::uint64_t pairs = domain ? domain->sum(listed) : listed;
    const double mean = static_cast<double>(pairs) / static_cast<double>(n);
    if (std::abs(mean / target - 1.0) < 0.01) break;
    h *= std::pow(target / std::max(mean, 0.5), 1.0 / D);
  }
  return h;
}

template double calibrate_smoothing_length(Particles<2>&, double, ParticleDomain<2>*);
template double calibrate_smoothing_length(Particles<3>&, double, ParticleDomain<3>*);

}  // namespace sphdisk
