#include "app/rate_sampling_scatter.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "app/ring_analysis.hpp"
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

double rate_sampling_scatter(const RingSolution& sol, const std::vector<RingBin>& bins, double tau, std::size_t particles,
                             int draws, std::uint64_t seed) {
  if (particles == 0 || bins.empty() || !(tau > 0) || draws < 2) return 0.0;
  std::vector<double> share(bins.size());
  double bins_mass = 0;
  for (std::size_t b = 0; b < bins.size(); ++b) bins_mass += share[b] = bins[b].sigma_ana_annulus * bins[b].area();
  if (!(bins_mass > 0)) return 0.0;
  for (double& s : share) s /= bins_mass;
  // The analytic annulus means at tau (0.5 + 0.0005 i), i = 0 .. 2000: the fit's two grids, each
  // profile computed when a draw first needs it.
  constexpr int kFine = 2000;
  std::vector<std::vector<double>> profiles(kFine + 1);
  auto l1_at = [&](int i, const std::vector<double>& sigma) {
    std::vector<double>& ana = profiles[static_cast<std::size_t>(i)];
    if (ana.empty())
      for (const RingBin& b : bins) ana.push_back(sol.annulus_mean_surface_density(b.r_lo, b.r_hi, tau * (0.5 + 0.0005 * i)));
    double num = 0, den = 0;
    for (std::size_t b = 0; b < bins.size(); ++b) num += std::abs(sigma[b] - ana[b]), den += ana[b];
    return den > 0 ? num / den : 0.0;
  };
  auto best_in = [&](int lo, int hi, int stride, const std::vector<double>& sigma) {
    int best = lo;
    double best_l1 = l1_at(lo, sigma);
    for (int i = lo + stride; i <= hi; i += stride)
      if (const double l1 = l1_at(i, sigma); l1 < best_l1) best = i, best_l1 = l1;
    return best;
  };
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
    const int coarse = best_in(0, kFine, 10, sigma);
    const int fine = best_in(std::max(coarse - 10, 0), std::min(coarse + 10, kFine), 1, sigma);
    const double rate = 0.5 + 0.0005 * fine;
    sum += rate, sum_sq += rate * rate;
  }
  const double mean = sum / draws;
  return std::sqrt(std::max(sum_sq / draws - mean * mean, 0.0) * draws / (draws - 1.0));
}

}  // namespace sphdisk
