#pragma once
// The scatter density (PairDensity::Scatter, physics_params.hpp): each particle's density from its
// neighbours' kernels rather than its own,
//   rho_s,i = m_i W(0, h_i) + sum_{j != i} m_j W(|x_i - x_j|, h_j),
// whose logarithm the consistent viscous force compares in S_i ln(rho_j / rho_i). The gather sum
// rho_i = sum_j m_j W(r_ij, h_i) (density.hpp) is biased by (kappa/2) h_i^2 lap rho, which at a
// fixed neighbour number grows without bound in a profile's sparse wings (h^2 ~ 1/rho); the scatter
// sum's bias, (kappa/2) lap(h^2 rho), vanishes in 2D at a fixed neighbour number (docs/physics.md
// sec. 2). It needs every h, so it is summed after the h solve, on the velocity-gradient loop's
// lists (viscous_stress.hpp): each pair once, i receives m_j W(r, h_j) and j receives m_i W(r, h_i)
// (add_scatter_list, list_sums.hpp). Computed for the writable particles, like the stress, and
// complete where the stress is.
// Reads: pos, mass, h. Writes: scatter_density.
#include <cstdint>
#include <span>
#include <vector>

#include "core/overwrite_vector.hpp"
#include "core/particles.hpp"
#include "core/snug_resize.hpp"
#include "parallel/loops.hpp"
#include "physics/kernel_scales.hpp"
#include "physics/list_sums.hpp"
#include "physics/pair_terms.hpp"
#include "physics/physics_params.hpp"

namespace sphdisk {

// Scratch of the scatter sums, kept by the caller between evaluations.
struct ScatterDensityScratch {
  OverwriteVector<KernelScale> scales;
  std::vector<double> sums;
};

// The sums' inputs for the m writable particles, zeroed; what the list loop reads and writes.
// scales: every particle's kernel scale where the caller has them (kernel_scales.hpp), else null and
// they are made in scratch.
template <int D>
ScatterListData<D> prepare_scatter_sums(const Particles<D>& p, std::size_t m, const PhysicsParams& phys,
                                        const KernelScale* scales, ScatterDensityScratch& scratch) {
  const KernelScale* s = scales ? scales : fill_kernel_scales(p, phys.kernel, scratch.scales, "velocity_gradient");
  grow_snug(scratch.sums, m);
  par::for_each(m, [&](std::size_t i) { scratch.sums[i] = 0.0; }, "velocity_gradient");
  return {p.pos.data(), p.mass.data(), s, scratch.sums.data(), m, phys.kernel};
}

// A list loop's body f(i, js, F) that runs `body` on the list, then adds the list's scatter terms.
template <int D, class Body>
auto with_scatter_sums(Body body, const ScatterListData<D>& s) {
  return [body, s](std::uint32_t i, std::span<const std::uint32_t> js, std::span<float> F) {
    body(i, js, F);
    double sum_i = 0.0;
    add_scatter_list(s, i, js, sum_i);
    if (i < s.writable) s.sums[i] += sum_i;
  };
}

// Particle i's scatter density from its complete sums: the self term added.
template <int D>
double settle_scatter_density(Particles<D>& p, std::size_t i, const ScatterListData<D>& s) {
  const double self_W = with_kernel(s.kernel, [&](auto k) { return pair_kernel_values<decltype(k)>(s.scales[i], s.scales[i], 0.0).i; });
  return p.scatter_density[i] = s.sums[i] + density_term(p.mass[i], self_W);
}

}  // namespace sphdisk
