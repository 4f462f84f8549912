#include "app/run_setup.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "core/error.hpp"
#include "physics/kernels.hpp"
#include "problems/power_law_disc.hpp"

namespace sphdisk {

std::vector<double> output_times(const Config& cfg, const Setup& setup) {
  if (!cfg.output_times.empty()) return cfg.output_times;
  std::vector<double> t;
  const double period = 2.0 * std::numbers::pi * std::pow(cfg.output_orbit_radius, 1.5);
  for (double orbits : cfg.output_orbits) t.push_back(orbits * period);
  if (t.empty())
    for (double tau : cfg.output_tau) t.push_back(setup.time_of_tau(tau));
  return t;
}

Setup make_setup(const Config& cfg) {
  Setup s;
  // Code units: length r0, mass M, G = 1 (core/units.hpp).
  s.units = UnitSystem::from_solar(cfg.ring_radius, cfg.central_mass);
  const double rsun2_per_s = cgs::solar_radius * cgs::solar_radius * s.units.time_s / (s.units.length_cm * s.units.length_cm);
  s.phys.gm = 1.0;
  s.phys.nu = cfg.viscosity * rsun2_per_s;
  s.phys.nu_bulk = cfg.bulk_viscosity * rsun2_per_s;
  s.phys.bulk_ratio = cfg.bulk_viscosity_ratio;
  s.phys.alpha_ss = cfg.alpha_ss;
  s.phys.eos = eos_from_name(cfg.eos);
  // c_s at r0: given in km/s or as H/R = c_s / v_Kepler(r0), raised where needed to keep nu <= alpha_max c_s^2 /
  // Omega(r0); v_Kepler(r0) and Omega(r0) are 1 in code units.
  const double given = cfg.aspect_ratio > 0 ? cfg.aspect_ratio : cfg.sound_speed * 1e5 / s.units.velocity_cm_per_s();
  s.phys.sound_speed = cfg.alpha_max > 0 ? std::max(given, std::sqrt(s.phys.nu / cfg.alpha_max)) : given;
  s.phys.sound_speed_index = cfg.sound_speed_index;
  s.phys.evolve_energy = cfg.evolve_energy;
  s.phys.av_alpha = cfg.av_alpha;
  s.phys.av_beta = cfg.av_beta;
  s.phys.av_limiter = cfg.av_limiter == "balsara";
  s.phys.av_switch = cfg.av_switch == "morris_monaghan";
  s.phys.av_alpha_min = cfg.av_alpha_min;
  s.phys.gradient_correction = gradient_correction_from_name(cfg.gradient_correction);
  s.phys.force_correction = cfg.force_correction;
  s.phys.viscous_force = viscous_force_from_name(cfg.resolved_viscous_force());
  s.phys.pair_density = pair_density_from_name(cfg.pair_density);
  s.phys.kernel = kernel_from_name(cfg.kernel);
  s.phys.accretion_radius = cfg.accretion_radius;
  s.ring.solution = RingSolution{cfg.disc_mass / cfg.central_mass, 1.0, s.phys.nu};
  s.ring.tau_start = cfg.tau_start;
  ParticlePlacement& placed = s.ring.placement;  // the ring's, and the disc's below
  placed.particles = static_cast<std::size_t>(cfg.particles);
  placed.seed = static_cast<std::uint64_t>(cfg.seed);
  placed.stratified = placement_from_name(cfg.placement) == Placement::Stratified;
  if (s.phys.eos != EquationOfState::None) {
    placed.sound_speed = s.phys.sound_speed;
    placed.sound_speed_index = s.phys.eos == EquationOfState::LocallyIsothermal ? cfg.sound_speed_index : 0.0;
  }
  s.ring.accretion_radius = cfg.accretion_radius;
  s.disc = cfg.problem == "disc";
  if (s.disc) {
    s.disc_sampling = power_law_sampling({cfg.inner_radius, cfg.outer_radius, cfg.sigma_index, cfg.disc_mass / cfg.central_mass});
    s.disc_sampling.placement = placed;
  }
  s.phys.gamma = cfg.gamma;
  s.sedov = cfg.problem == "sedov";
  if (s.sedov) {
    s.phys.gm = 0.0;  // no point mass, nothing to accrete
    s.phys.accretion_radius = 0.0;
    s.sedov_blast = SedovBlast{placed.particles, cfg.blast_energy, cfg.gamma, cfg.neighbours};
  }
  s.tau_rate = 12.0 * s.phys.nu;
  return s;
}

// Refuse up front what cannot fit: ~200 bytes of fields and scratch per particle plus the
// neighbour lists and pair factors. A rough estimate, close to the measured peaks with stored lists
// at 60 neighbours (docs/performance.md, "Memory per particle").
void check_memory(std::size_t particles, double neighbours, bool adaptive) {
  // Fields ~224 B, lists + pair factors 12 B per neighbour, adaptive smoothing's candidate lists
  // 4 B per candidate (1.1^D more than neighbours).
  const double bytes_estimate = static_cast<double>(particles) * (224.0 + (adaptive ? 17.0 : 12.0) * neighbours);
  const double bytes_available = static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
  if (bytes_estimate > 0.9 * bytes_available) {
    char msg[256];
    std::snprintf(msg, sizeof msg, "%zu particles need about %.1f GiB but this machine has %.1f GiB; use fewer particles",
                  particles, bytes_estimate / (1ull << 30), bytes_available / (1ull << 30));
    throw UserError(msg);
  }
}

}  // namespace sphdisk
