#pragma once
// Radial profiles of any disc around the point mass (a 3D one seen from above, with its heights) (docs/physics.md sec. 4 "Diagnostics"):
// what `sphdisk analyze` reports for runs that are not the viscous ring, which has an analytic
// solution (ring_analysis.hpp). Bins of equal width in r between the innermost and outermost
// particle, or a given range.
#include <string>
#include <vector>

#include "core/particles.hpp"
#include "io/snapshot.hpp"

namespace sphdisk {

struct DiscBin {
  double r_lo = 0, r_hi = 0;
  std::size_t count = 0;
  double sigma = 0;     // particle mass in the annulus / its area
  double vr = 0;        // mass-weighted mean radial velocity (with the particles' epicycles)
  double vr_drift = 0;  // mass-weighted mean guiding-centre drift 2 j (dj/dt) / (G M): v_r without epicycles
  double j = 0;         // mass-weighted mean specific angular momentum x v_y - y v_x
  double mdot = 0;      // mass flux through the annulus' mid radius, inward positive: -2 pi r Sigma <v_r>
  double z_rms = 0;     // 3D: the mass-weighted rms height (the scale height H of a Gaussian layer)
};

struct DiscProfiles {
  double time = 0;
  std::size_t particles = 0;
  double mass = 0;           // in the particles
  double accreted_mass = 0;  // by the point mass (Header AccretedMass)
  double initial_mass = 0;   // Header DiskMass (0: not recorded)
  double gm = 1;             // G M of the point mass in the file's units
  bool heights = false;      // 3D: the bins' z_rms are filled in
  std::vector<DiscBin> bins;
};

// The ring set-up, with its analytic solution: Header Problem = "ring", or, in files without it,
// one with the ring's positive ViscousTime, KinematicViscosity and DiskMass from a run that read no
// initial conditions from a file (any other file gets radial profiles).
bool is_ring_snapshot(const SnapshotMeta& meta);

// nbins bins over [r_min, r_max] in the file's length unit; r_max <= r_min: the particles' extent.
// z: a 3D run's heights, one per particle (null in 2D).
DiscProfiles disc_profiles(const Particles<2>& p, const SnapshotMeta& meta, int nbins = 50, double r_min = 0,
                           double r_max = 0, const std::vector<double>* z = nullptr);

std::string disc_profiles_table(const DiscProfiles& d);
std::string disc_profiles_json(const DiscProfiles& d);

}  // namespace sphdisk
