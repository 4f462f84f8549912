#include "app/ring_fit.hpp"

#include <cmath>

#include "app/ring_analysis.hpp"

namespace sphdisk {

RingFitGrid::RingFitGrid(const RingSolution& sol, const std::vector<RingBin>& bins, double tau)
    : sol_(sol), bins_(bins), tau_(tau), profiles_(kHi - kLo + 1) {}

double RingFitGrid::l1_at(int i, const std::vector<double>& sigma) {
  std::vector<double>& ana = profiles_[static_cast<std::size_t>(i - kLo)];
  if (ana.empty())
    for (const RingBin& b : bins_) ana.push_back(sol_.annulus_mean_surface_density(b.r_lo, b.r_hi, tau_at(i)));
  double num = 0, den = 0;
  for (std::size_t b = 0; b < bins_.size(); ++b) num += std::abs(sigma[b] - ana[b]), den += ana[b];
  return den > 0 ? num / den : 0.0;
}

std::pair<int, double> RingFitGrid::best_in(int lo, int hi, int stride, const std::vector<double>& sigma) {
  int best = lo;
  double best_l1 = l1_at(lo, sigma);
  for (int i = lo + stride; i <= hi; i += stride)
    if (const double l1 = l1_at(i, sigma); l1 < best_l1) best = i, best_l1 = l1;
  return {best, best_l1};
}

std::pair<double, double> RingFitGrid::fit(const std::vector<double>& sigma) {
  const int coarse = best_in(0, kLast, kStride, sigma).first;
  const auto [fine, l1] = best_in(coarse - kStride, coarse + kStride, 1, sigma);
  return {tau_at(fine), l1};
}

}  // namespace sphdisk
