#include "problems/power_law_disc.hpp"

#include <cmath>
#include <numbers>

namespace sphdisk {

double power_law_surface_density(const PowerLawDisc& d, double R) {
  if (R < d.inner_radius || R > d.outer_radius) return 0.0;
  // M = 2 pi Sigma_0 integral R^(1-p) dR over [R_in, R_out].
  const double e = 2.0 - d.sigma_index;
  const double integral = std::abs(e) < 1e-12 ? std::log(d.outer_radius / d.inner_radius)
                                              : (std::pow(d.outer_radius, e) - std::pow(d.inner_radius, e)) / e;
  return d.mass / (2.0 * std::numbers::pi * integral) * std::pow(R, -d.sigma_index);
}

DiscSampling power_law_sampling(const PowerLawDisc& d) {
  DiscSampling s;
  s.surface_density = [d](double R) { return power_law_surface_density(d, R); };
  s.r_lo = d.inner_radius;
  s.r_hi = d.outer_radius;
  s.mass = d.mass;
  s.what = "disc";
  return s;
}

}  // namespace sphdisk
