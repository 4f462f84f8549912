#pragma once
// The best-fit viscous time tau* of a binned ring profile (docs/physics.md sec. 4, "Diagnostics"):
// the least annulus-mass L1 against the analytic annulus means over 0.5-1.5 tau in steps of
// 0.005 tau, then within +-0.005 tau of the best in steps of 0.0005 tau (the first minimum of each
// scan). One grid of profiles serves the run's fit and the random sets of rate_sampling_scatter.hpp.
#include <utility>
#include <vector>

#include "problems/ring_analytic.hpp"

namespace sphdisk {

struct RingBin;

class RingFitGrid {
 public:
  RingFitGrid(const RingSolution& sol, const std::vector<RingBin>& bins, double tau);
  // (tau*, the annulus-mass L1 there) of the binned Sigma `sigma` (one value per bin).
  std::pair<double, double> fit(const std::vector<double>& sigma);

 private:
  // Grid points tau (0.5 + 0.0005 i): the coarse scan takes every kStride-th of 0 .. kLast, the fine
  // one every point within kStride of its best, so the grid reaches kLo .. kHi.
  static constexpr int kLast = 2000, kStride = 10, kLo = -kStride, kHi = kLast + kStride;
  double tau_at(int i) const { return tau_ * (0.5 + 0.0005 * i); }
  double l1_at(int i, const std::vector<double>& sigma);
  std::pair<int, double> best_in(int lo, int hi, int stride, const std::vector<double>& sigma);

  const RingSolution& sol_;
  const std::vector<RingBin>& bins_;
  double tau_;
  std::vector<std::vector<double>> profiles_;  // the analytic annulus means at grid point i - kLo, when first needed
};

}  // namespace sphdisk
