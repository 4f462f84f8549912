#pragma once
// The scatter density (PairDensity::Scatter, physics_params.hpp): each particle's density from its
// neighbours' kernels rather than its own,
//   rho_s,i = m_i W(0, h_i) + sum_{j != i} m_j W(|x_i - x_j|, h_j),
// whose logarithm the consistent viscous force compares in S_i ln(rho_j / rho_i). The gather sum
// rho_i = sum_j m_j W(r_ij, h_i) (density.hpp) is biased by (kappa/2) h_i^2 lap rho, which at a
// fixed neighbour number grows without bound in a profile's sparse wings (h^2 ~ 1/rho); the scatter
// sum's bias, (kappa/2) lap(h^2 rho), vanishes in 2D at a fixed neighbour number (docs/physics.md
// sec. 2). Each pair once: i receives m_j W(r, h_j) and j receives m_i W(r, h_i) (add_scatter_list,
// list_sums.hpp). Computed for the writable particles, like rho; the pairs must hold every
// neighbour within either particle's support, as the pair sources do.
// Reads: pos, mass, h. Writes: scatter_density.
#include <cmath>
#include <span>
#include <vector>

#include "core/overwrite_vector.hpp"
#include "core/pair_source.hpp"
#include "core/particles.hpp"
#include "parallel/loops.hpp"
#include "physics/kernel_scales.hpp"
#include "physics/pair_terms.hpp"
#include "physics/physics_params.hpp"
#include "physics/viscous_stress.hpp"

namespace sphdisk {

// Scratch of the scatter sums, kept by the caller between evaluations.
struct ScatterDensityScratch {
  OverwriteVector<KernelScale> scales;
  std::vector<double> sums;
};

template <int D, PairSource Pairs>
void compute_scatter_density(Particles<D>& p, const Pairs& pairs, const PhysicsParams& phys, ScatterDensityScratch& scratch) {
  const KernelScale* s = fill_kernel_scales(p, phys.kernel, scratch.scales, "density");
  const std::size_t m = pairs.writable();
  std::vector<double>& sums = scratch.sums;
  sum_pair_lists(
      pairs, sums,
      [&](std::uint32_t i, std::span<const std::uint32_t> js, std::span<const float>, double& sum_i) {
        add_scatter_list(ScatterListData<D>{p.pos.data(), p.mass.data(), s, sums.data(), m, phys.kernel}, i, js, sum_i);
      },
      "density", FactorUse::Ignore);
  par::for_each(
      m,
      [&](std::size_t i) {
        const double self_W = pair_kernel_values(phys.kernel, s[i], s[i], 0.0).i;
        p.scatter_density[i] = sums[i] + density_term(p.mass[i], self_W);
      },
      "density");
}

}  // namespace sphdisk
