#include "app/rate_sampling_scatter.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "app/ring_analysis.hpp"
#include "app/ring_fit.hpp"
#include "core/portable_random.hpp"

namespace sphdisk {

namespace {

// A binomial (n, p) number: by inversion where n p < 30 (the wings' bins), else the normal
// approximation rounded to the nearest count (the core's bins, thousands of particles each).
std::size_t binomial(std::size_t n, double p, std::mt19937_64& g) {
  if (n == 0 || !(p > 0)) return 0;
  if (p >= 1) return n;
  if (p > 0.5) return n - binomial(n, 1.0 - p, g);
  const double dn = static_cast<double>(n), mean = dn * p;
  if (mean < 30) {
    double u = uniform01(g), pk = std::exp(dn * std::log1p(-p));
    std::size_t k = 0;
    while (u > pk && k < n) {
      u -= pk;
      pk *= static_cast<double>(n - k) / static_cast<double>(k + 1) * p / (1.0 - p);
      ++k;
    }
    return k;
  }
  const double u1 = uniform01(g);
  const double k = std::round(mean + std::sqrt(mean * (1.0 - p)) * standard_normal(u1, uniform01(g)));
  return static_cast<std::size_t>(std::clamp(k, 0.0, dn));
}

}  // namespace

double rate_sampling_scatter(RingFitGrid& grid, const std::vector<RingBin>& bins, double tau, std::size_t particles,
                             int draws, std::uint64_t seed) {
  if (particles == 0 || bins.empty() || !(tau > 0) || draws < 2) return 0.0;
  std::vector<double> share(bins.size());
  double bins_mass = 0;
  for (std::size_t b = 0; b < bins.size(); ++b) bins_mass += share[b] = bins[b].sigma_ana_annulus * bins[b].area();
  if (!(bins_mass > 0)) return 0.0;
  for (double& s : share) s /= bins_mass;
  std::mt19937_64 gen(seed);
  std::vector<double> sigma(bins.size());
  double sum = 0, sum_sq = 0;
  for (int d = 0; d < draws; ++d) {
    std::size_t left = particles;  // the multinomial as a chain of binomials
    double share_left = 1.0;
    for (std::size_t b = 0; b < bins.size(); ++b) {
      const std::size_t n = binomial(left, share_left > 0 ? std::min(share[b] / share_left, 1.0) : 0.0, gen);
      left -= n;
      share_left -= share[b];
      sigma[b] = static_cast<double>(n) * (bins_mass / static_cast<double>(particles)) / bins[b].area();
    }
    const double rate = grid.fit(sigma).first / tau;
    sum += rate, sum_sq += rate * rate;
  }
  const double mean = sum / draws;
  return std::sqrt(std::max(sum_sq / draws - mean * mean, 0.0) * draws / (draws - 1.0));
}

}  // namespace sphdisk
