#pragma once
// The viscous stress (viscous_stress.hpp) and the accelerations (forces.hpp) in one pass over the
// pairs, for pair forms that join two loops (Pairs::for_each_list_joined, pair_scan.hpp: pairs
// searched anew are then searched once for both loops): the same terms in the same order, so the
// same bits, as compute_viscous_stress followed by compute_accelerations. Not with the force
// correction's heating (with an energy equation), whose loop must run between the two.
#include <cmath>
#include <vector>

#include "core/pair_source.hpp"
#include "core/particles.hpp"
#include "physics/forces.hpp"
#include "physics/physics_params.hpp"
#include "physics/scatter_density.hpp"
#include "physics/viscous_stress.hpp"

namespace sphdisk {

// With the scatter density (scatter_density.hpp) a particle's is settled with its stress, and its
// ln rho for the force lists that follow.
template <int D, JoinsLoops Pairs>
void compute_stress_and_accelerations(Particles<D>& p, const Pairs& pairs, const PhysicsParams& phys,
                                      GradientSumsArray<D>& sums, ForceScratch& scratch, ScatterDensityScratch& scatter,
                                      bool with_gravity) {
  const std::size_t m = pairs.writable();
  zero_sums(m, sums, phys.gradient_correction == GradientCorrection::Mixed);
  const ForceListData<D> d = prepare_forces(p, m, phys, scratch, with_gravity, particles_read_by(pairs));
  const auto gradient = sum_lists_into(sums, m, gradient_pair_terms(p, sums, m, phys, d.scales));
  if (phys.keeps_scatter_density()) {
    const ScatterListData<D> sd = prepare_scatter_sums(p, m, phys, d.scales, scatter);
    pairs.for_each_list_joined(with_scatter_sums(gradient, sd),
                               [&](std::uint32_t i) {
                                 scratch.log_rho[i] = std::log(settle_scatter_density(p, i, sd));
                                 settle_stress(p, i, sums[i], phys);
                               },
                               force_list_body(p, d), "gradient_and_forces");
    return;
  }
  pairs.for_each_list_joined(gradient, [&](std::uint32_t i) { settle_stress(p, i, sums[i], phys); }, force_list_body(p, d),
                             "gradient_and_forces");
}

}  // namespace sphdisk
