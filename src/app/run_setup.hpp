#pragma once
// What a run's configuration implies in code units (length r0, mass M, G = 1; core/units.hpp):
// the physics parameters, the ring's or the disc's set-up, the viscous-time clock and the output times; and the
// up-front refusal of a run that cannot fit in memory.
#include <cstddef>
#include <vector>

#include "core/config.hpp"
#include "core/units.hpp"
#include "physics/physics_params.hpp"
#include "problems/disc_sampling.hpp"
#include "problems/ring_setup.hpp"
#include "problems/sedov_blast.hpp"

namespace sphdisk {

struct Setup {
  UnitSystem units;
  PhysicsParams phys;
  RingSetup ring;
  bool disc = false;        // problem.type = "disc": the particles from disc_sampling, not the ring
  DiscSampling disc_sampling;
  bool sedov = false;       // problem.type = "sedov": the blast wave (no point mass), not the ring
  SedovBlast sedov_blast;
  // The set-up's name, as snapshots record it (Header Problem).
  const char* problem_name() const { return sedov ? "sedov" : disc ? "disc" : "ring"; }
  double tau_rate;  // d tau / dt (r0 = 1); nu = 0 (pure Kepler test): tau then stands for the time
  double tau_of_time(double t) const { return tau_rate > 0 ? t * tau_rate : t; }
  double time_of_tau(double tau) const { return tau_rate > 0 ? tau / tau_rate : tau; }
};

Setup make_setup(const Config& cfg);

// The output times in code units: output.times as given, output.orbits times the period 2 pi R^1.5
// at R = output.orbit_radius (G M = r0 = 1), or output.tau through the viscous time.
std::vector<double> output_times(const Config& cfg, const Setup& setup);

// Refuses up front what cannot fit: ~200 bytes of fields and scratch per particle plus the
// neighbour lists and pair factors.
void check_memory(std::size_t particles, double neighbours, bool adaptive);

}  // namespace sphdisk
