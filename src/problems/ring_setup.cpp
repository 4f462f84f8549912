#include "problems/ring_setup.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <stdexcept>
#include <vector>

#include "core/error.hpp"
#include "core/named_choice.hpp"
#include "problems/disc_sampling.hpp"

namespace sphdisk {

Placement placement_from_name(std::string_view name) {
  static constexpr NamedChoice<Placement> kNames[] = {{"random", Placement::Random}, {"stratified", Placement::Stratified}};
  return choice_from_name<Placement>("problem.placement", name, kNames);
}

namespace {

// Radial range holding all but a negligible part of the mass: the profile is close to a Gaussian
// of variance tau/2 around r0 (docs/physics.md sec. 4).
void radial_range(const RingSetup& s, double& r_lo, double& r_hi) {
  const double r0 = s.solution.ring_radius;
  const double width = std::sqrt(0.5 * s.tau_start) * r0;
  r_lo = std::max(s.accretion_radius * r0, r0 - 15.0 * width);
  r_lo = std::max(r_lo, 1e-6 * r0);
  r_hi = r0 + 25.0 * width;
}

DiscSampling ring_sampling(const RingSetup& s) {
  DiscSampling d;
  d.surface_density = [sol = s.solution, tau = s.tau_start](double r) { return sol.surface_density(r, tau); };
  d.radial_velocity = [sol = s.solution, tau = s.tau_start](double r) { return sol.radial_velocity(r, tau); };
  radial_range(s, d.r_lo, d.r_hi);
  d.mass = s.solution.disc_mass;
  d.placement = s.placement;
  d.what = "ring";
  return d;
}

}  // namespace

double ring_scale_height(const RingSetup& s, double R) { return scale_height(ring_sampling(s), R); }

template <int D>
Particles<D> make_ring(const RingSetup& s) { return make_ring<D>(s, 0, 1); }

template <int D>
Particles<D> make_ring(const RingSetup& s, std::size_t share, std::size_t shares) {
  return sample_disc<D>(ring_sampling(s), share, shares);
}

template Particles<2> make_ring(const RingSetup&);
template Particles<3> make_ring(const RingSetup&);
template Particles<2> make_ring(const RingSetup&, std::size_t, std::size_t);
template Particles<3> make_ring(const RingSetup&, std::size_t, std::size_t);

double ring_smoothing_length(const RingSetup& s, double neighbours) {
  double r_lo, r_hi;
  radial_range(s, r_lo, r_hi);
  const double m = s.solution.disc_mass;
  double integral = 0, prev = 0;
  const std::size_t k_max = 20000;
  for (std::size_t k = 0; k < k_max; ++k) {
    const double r = r_lo + (r_hi - r_lo) * static_cast<double>(k) / static_cast<double>(k_max - 1);
    const double sig = s.solution.surface_density(r, s.tau_start) / m;
    const double f = sig * sig * 2.0 * std::numbers::pi * r;
    if (k > 0) integral += 0.5 * (f + prev) * (r_hi - r_lo) / static_cast<double>(k_max - 1);
    prev = f;
  }
  return std::sqrt(neighbours / (4.0 * std::numbers::pi * static_cast<double>(s.placement.particles) * integral));
}

}  // namespace sphdisk
