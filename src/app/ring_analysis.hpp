#pragma once
// Comparison of a ring snapshot with the analytic solution (P98 sec. 5.3, Fig. 8): particle
// surface densities averaged in radial bins (50 over 0.05 - 2.05 r0 by default), binned radial
// velocity, per-particle scatter and L1 errors.
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "core/particles.hpp"
#include "io/snapshot.hpp"
#include "problems/ring_analytic.hpp"

namespace sphdisk {

struct RingBin {
  double r_lo, r_hi;
  std::size_t count = 0;
  double sigma_sph = 0;   // mean particle Sigma in the bin
  double sigma_ana = 0;   // mean analytic Sigma at the same particles' radii (like with like)
  double sigma_noself = 0;  // mean particle Sigma without its self term m W(0, h): the summation
                            // over the other particles, unbiased where they are disordered
  double vr_sph = 0;      // mean particle v_r
  double vr_ana = 0;      // mean analytic v_r at the same radii
  double vr_drift = 0;    // mean guiding-centre drift 2 j (dj/dt) / (G M): v_r without epicycles
  double sigma_mass = 0;       // particle mass in the annulus / its area
  double sigma_ana_annulus = 0;  // analytic annulus mean of Sigma
  double area() const { return std::numbers::pi * (r_hi * r_hi - r_lo * r_lo); }
};

// The annulus-mass L1 and the sampling floor from one radial region's bins (both in the units of
// RingComparison::mass_sigma_l1, so the regions add up to it and to sampling_floor).
struct RegionL1 {
  const char* name;
  double lo, hi;  // in r0
  double l1 = 0, floor = 0;
};

struct RingComparison {
  double tau = 0;
  std::size_t particles = 0;
  std::vector<RingBin> bins;
  double sigma_l1 = 0;         // sum |<Sigma_sph> - <Sigma_ana>| / sum <Sigma_ana> over populated bins
  double vr_l1 = 0;            // sum n_b |<v_r> - <v_r,ana>| / sum n_b |<v_r,ana>| (n_b: particles in
                               // bin b) over bins where |<v_r,ana>| >= 20% of its maximum
  double vr_drift_l1 = 0;      // same for the guiding-centre drift velocity
  double mass_sigma_l1 = 0;    // annulus mass / area against the analytic annulus means
  double sampling_floor = 0;   // expected mass_sigma_l1 of N particles drawn at random from the exact
                               // profile (binomial bin counts): the error a perfect code still shows
  double tau_fit = 0;          // viscous time whose analytic annulus means fit the binned mass best
                               // (least mass_sigma_l1); tau_fit / tau < 1: the ring spread too slowly
  double mass_sigma_l1_at_fit = 0;  // mass_sigma_l1 against the profile at tau_fit
  double rate_sampling_sd = 0;  // standard deviation of tau_fit / tau for N particles drawn at random
                                // from the exact profile (rate_sampling_scatter.hpp): the noise of the rate
  // mass_sigma_l1 and sampling_floor split over the inner wing, the core and the outer wing: where a
  // front or a deficit lies, against where the sampling noise alone would put the error.
  std::vector<RegionL1> regions{
      {"inner wing", 0.0, 0.5}, {"core", 0.5, 1.5}, {"outer wing", 1.5, std::numeric_limits<double>::infinity()}};
  bool sph_sigma = true;       // the particles' Density is a surface density (2D runs): the SPH Sigma
                               // measures (sigma_l1, sigma_scatter, the core biases, the bins'
                               // sigma_sph, sigma_noself, sigma_ana) are filled in; 3D runs: not
  double sigma_scatter = 0;    // rms of Sigma_i / Sigma_ana(r_i) - 1 over particles with Sigma_ana > 1% of peak
  double core_sigma_bias = 0;  // mean Sigma_i / Sigma_ana(r_i) - 1 over particles with 0.9 <= r / r0 <= 1.1
  double core_sigma_noself_bias = 0;  // the same for Sigma without its self term
  double mass = 0;             // mass in the particles
  double accreted_mass = 0;
  double initial_mass = 0;      // the disc mass at the start (Header DiskMass; 0: not recorded)
};

// rate_draws: the random particle sets behind rate_sampling_sd (0: none, the figure left at 0).
RingComparison compare_ring(const Particles<2>& p, const SnapshotMeta& meta, int nbins = 50, double r_min = 0.05,
                            double r_max = 2.05, int rate_draws = 200);

std::string ring_comparison_table(const RingComparison& c);
std::string ring_comparison_json(const RingComparison& c);

}  // namespace sphdisk
