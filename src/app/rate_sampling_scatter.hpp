#pragma once
// How much the ring's best-fit viscous time scatters from sampling alone: sets of N particles drawn
// at random from the exact profile (P98 5.2's random placement, with no dynamics at all) give
// tau*/tau != 1 through the binomial noise of their annulus masses. `sphdisk analyze` prints this
// standard deviation beside a run's tau*/tau, so that a departure can be told from noise
// (docs/physics.md sec. 4, "Diagnostics").
#include <cstddef>
#include <cstdint>
#include <vector>

namespace sphdisk {

struct RingBin;
class RingFitGrid;

// The standard deviation of tau*/tau over `draws` sets of `particles` particles drawn from the
// analytic profile at tau into `bins` (multinomial counts over the bins' shares of the analytic
// mass, as the sampling floor assumes), each fitted on `grid` as compare_ring fits the run
// (ring_fit.hpp). A fixed seed: the same figure for the same snapshot on any machine.
double rate_sampling_scatter(RingFitGrid& grid, const std::vector<RingBin>& bins, double tau, std::size_t particles,
                             int draws = 200, std::uint64_t seed = 1);

}  // namespace sphdisk
