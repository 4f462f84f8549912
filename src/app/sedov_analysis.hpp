#pragma once
// A Sedov-Taylor blast wave's snapshot against the similarity solution (problems/sedov_solution.hpp;
// docs/physics.md sec. 5): what `sphdisk analyze` reports for problem.type = "sedov".
// Out to 1.5 shock radii, or to the cube's inscribed sphere where that is nearer: the L1 norms of the
// particles' SPH density, radial velocity and pressure against the solution at each particle's
// radius, and spherical (circular in 2D) shells of equal width with the particles' means beside the
// solution's shell means.
#include <string>
#include <vector>

#include "core/particles.hpp"
#include "io/snapshot.hpp"

namespace sphdisk {

struct SedovBin {
  double r_lo = 0, r_hi = 0;
  std::size_t count = 0;
  double rho = 0, rho_ana = 0;  // mean particle density; the solution's mean over the shell's volume
  double vr = 0, vr_ana = 0;    // mean radial velocity
  double p = 0, p_ana = 0;      // mean pressure (gamma - 1) rho u
};

struct SedovComparison {
  double time = 0;
  int dimension = 3;
  std::size_t particles = 0;
  double gamma = 5.0 / 3.0, energy = 1, rho0 = 1;
  double shock_radius = 0;       // analytic
  double peak_radius = 0;        // the middle of the shell with the largest mean density (0: none)
  double peak_density = 0;       // that shell's mean density
  double rho_l1 = 0, vr_l1 = 0, p_l1 = 0;  // sum_i |f_i - f(r_i)| / sum_i |f(r_i)| over the particles
  double total_energy = 0;       // kinetic + internal of the particles
  double initial_energy = 0;     // the blast's plus the ambient gas's
  std::vector<SedovBin> bins;
};

template <int D>
SedovComparison compare_sedov(const Particles<D>& p, const SnapshotMeta& meta, int nbins = 50);

std::string sedov_comparison_table(const SedovComparison& c);
std::string sedov_comparison_json(const SedovComparison& c);

}  // namespace sphdisk
