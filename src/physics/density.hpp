#pragma once
// Density by summation (P98 eq. 4 with f = rho; physics.md sec. 2), self term included:
//   rho_i = sum_j m_j W(|x_i - x_j|, h_i).
// In 2D rho is the surface density Sigma.
// The particle volume m/rho, the weight of every later pair sum (eqs. 6, 8), is stored with it, and
// so are the kernel-gradient factors of every pair (pair_factors.hpp). With one global h the factor
// is dW(r, h)/dr / r; with variable h it is the pair average of dW(r, h_i)/dr / r and
// dW(r, h_j)/dr / r (interaction_lists.hpp), symmetric in i <-> j as momentum conservation needs.
// Computed for the particles that have lists (nl.size(): all of them, or a process's own particles
// when the rest are ghosts whose values come from their owners).
// Reads: pos, mass, h. Writes: rho, volume, pair factors.
#include "core/particles.hpp"
#include "core/snug_resize.hpp"
#include "neighbours/neighbour_lists.hpp"
#include "parallel/loops.hpp"
#include "physics/kernels.hpp"
#include "physics/pair_factors.hpp"

namespace sphdisk {

// pair_factor(k, j, r): the factor of list entry k (neighbour j at distance r).
template <class K, int D, class PairFactor>
double density_at(std::size_t i, const Particles<D>& p, const NeighbourLists& nl, const KernelAt<K, D>& kern,
                  float* factors, PairFactor&& pair_factor) {
  const Vec<D> xi = p.pos[i];
  double rho = p.mass[i] * kern.W(0.0);
  for (std::size_t k = nl.offsets[i]; k < nl.offsets[i + 1]; ++k) {
    const std::uint32_t j = nl.index[k];
    const double r = norm(xi - p.pos[j]);
    rho += p.mass[j] * kern.W(r);
    factors[k] = static_cast<float>(pair_factor(j, r));
  }
  return rho;
}

template <class K, int D>
double density_at(std::size_t i, const Particles<D>& p, const NeighbourLists& nl, const KernelAt<K, D>& kern,
                  float* factors) {
  return density_at(i, p, nl, kern, factors, [&kern](std::uint32_t, double r) { return kern.dW_over_r(r); });
}

// One global smoothing length.
template <class K, int D>
void compute_density(Particles<D>& p, const NeighbourLists& nl, const KernelAt<K, D>& kern, PairFactors& factors) {
  resize_snug(factors, nl.total());
  par::for_each(nl.size(), [&](std::size_t i) {
    p.rho[i] = density_at(i, p, nl, kern, factors.data());
    p.volume[i] = p.mass[i] / p.rho[i];
  }, "density");
}

// Per-particle smoothing lengths p.h. `kernels` is scratch (one bound kernel per particle).
template <class K, int D>
void compute_density(Particles<D>& p, const NeighbourLists& nl, std::vector<KernelAt<K, D>>& kernels,
                     PairFactors& factors) {
  resize_snug(factors, nl.total());
  kernels.resize(p.size(), KernelAt<K, D>(1.0));
  par::for_each(p.size(), [&](std::size_t i) { kernels[i] = KernelAt<K, D>(p.h[i]); }, "density");
  par::for_each(nl.size(), [&](std::size_t i) {
    const KernelAt<K, D>& ki = kernels[i];
    p.rho[i] = density_at(i, p, nl, ki, factors.data(), [&](std::uint32_t j, double r) {
      // One division per pair: (dW_i/dr + dW_j/dr) / (2 r); w'(0) = 0, so coincident particles get 0.
      return r > 0 ? (ki.dW_dr(r) + kernels[j].dW_dr(r)) / (2.0 * r) : 0.0;
    });
    p.volume[i] = p.mass[i] / p.rho[i];
  }, "density");
}

}  // namespace sphdisk
