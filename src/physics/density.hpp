#pragma once
// Density by summation (P98 eq. 4 with f = rho; physics.md sec. 2), self term included:
//   rho_i = sum_j m_j W(|x_i - x_j|, h).
// In 2D rho is the surface density Sigma.
// Reads: pos, mass. Writes: rho.
#include "core/particles.hpp"
#include "neighbours/neighbour_lists.hpp"
#include "parallel/loops.hpp"
#include "physics/kernels.hpp"

namespace sphdisk {

template <class K, int D>
double density_at(std::size_t i, const Particles<D>& p, const NeighbourLists& nl, const KernelAt<K, D>& kern) {
  const Vec<D> xi = p.pos[i];
  double rho = p.mass[i] * kern.W(0.0);
  for (const std::uint32_t* it = nl.begin(i); it != nl.end(i); ++it) {
    const std::uint32_t j = *it;
    rho += p.mass[j] * kern.W(norm(xi - p.pos[j]));
  }
  return rho;
}

template <class K, int D>
void compute_density(Particles<D>& p, const NeighbourLists& nl, const KernelAt<K, D>& kern) {
  par::for_each(p.size(), [&](std::size_t i) { p.rho[i] = density_at(i, p, nl, kern); }, "density");
}

}  // namespace sphdisk
