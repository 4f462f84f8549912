#pragma once
// Density by summation (P98 eq. 4 with f = rho; physics.md sec. 2), self term included:
//   rho_i = sum_j m_j W(|x_i - x_j|, h).
// In 2D rho is the surface density Sigma.
// The particle volume m/rho, the weight of every later pair sum (eqs. 6, 8), is stored with it, and
// so are the kernel-gradient factors of every pair (pair_factors.hpp).
// Reads: pos, mass. Writes: rho, volume, pair factors.
#include "core/particles.hpp"
#include "neighbours/neighbour_lists.hpp"
#include "parallel/loops.hpp"
#include "physics/kernels.hpp"
#include "physics/pair_factors.hpp"

namespace sphdisk {

template <class K, int D>
double density_at(std::size_t i, const Particles<D>& p, const NeighbourLists& nl, const KernelAt<K, D>& kern,
                  float* factors) {
  const Vec<D> xi = p.pos[i];
  double rho = p.mass[i] * kern.W(0.0);
  for (std::size_t k = nl.offsets[i]; k < nl.offsets[i + 1]; ++k) {
    const std::uint32_t j = nl.index[k];
    const double r = norm(xi - p.pos[j]);
    rho += p.mass[j] * kern.W(r);
    factors[k] = static_cast<float>(kern.dW_over_r(r));
  }
  return rho;
}

template <class K, int D>
void compute_density(Particles<D>& p, const NeighbourLists& nl, const KernelAt<K, D>& kern, PairFactors& factors) {
  factors.resize(nl.total());
  par::for_each(p.size(), [&](std::size_t i) {
    p.rho[i] = density_at(i, p, nl, kern, factors.data());
    p.volume[i] = p.mass[i] / p.rho[i];
  }, "density");
}

}  // namespace sphdisk
