#pragma once
// Density by summation (P98 eq. 4 with f = rho; physics.md sec. 2), self term included:
//   rho_i = sum_j m_j W(|x_i - x_j|, h_i).
// In 2D rho is the surface density Sigma.
// Each pair is visited once (pair_lists.hpp): its distance, both kernel values and its
// kernel-gradient factor (pair_factors.hpp) are computed once and serve both particles. With one
// global h the factor is dW(r, h)/dr / r; with variable h it is the pair average of dW(r, h_i)/dr / r
// and dW(r, h_j)/dr / r (pair_lists.hpp), symmetric in i <-> j as momentum conservation needs.
// The particle volume m/rho, the weight of every later pair sum (eqs. 6, 8), is stored with rho.
// Computed for the writable particles (pl.writable: all of them, or a process's own active
// particles when the rest are ghosts or inactive ones, which keep their values).
// Reads: pos, mass, h. Writes: rho, volume, pair factors.
#include "core/particles.hpp"
#include "core/snug_resize.hpp"
#include "neighbours/pair_lists.hpp"
#include "parallel/loops.hpp"
#include "physics/kernels.hpp"
#include "physics/pair_factors.hpp"

namespace sphdisk {

struct PairKernel {
  double w_i, w_j, factor;  // W(r, h_i), W(r, h_j), (1/r) dW/dr averaged over the pair
};

// pair_kernel_of(i) -> a function (j, r) -> PairKernel of i's pairs (holding i's kernel by value:
// a kernel read through a reference would be reloaded after every store to rho, which may alias
// it); self_W(i) = W(0, h_i).
template <int D, class SelfW, class PairKernelOf>
void sum_density(Particles<D>& p, const PairLists& pl, PairFactors& factors, SelfW&& self_W, PairKernelOf&& pair_kernel_of) {
  resize_snug(factors, pl.total());
  const std::size_t m = pl.writable;
  par::for_each(m, [&](std::size_t i) { p.rho[i] = p.mass[i] * self_W(i); }, "density");
  for_each_pair_list(pl, [&](std::uint32_t i, std::span<const std::uint32_t> js, std::size_t k0) {
    const Vec<D> xi = p.pos[i];
    const double mi = p.mass[i];
    const auto pair_kernel = pair_kernel_of(i);
    double rho_i = 0.0;
    for (std::size_t q = 0; q < js.size(); ++q) {
      const std::uint32_t j = js[q];
      const PairKernel w = pair_kernel(j, norm(xi - p.pos[j]));
      factors[k0 + q] = static_cast<float>(w.factor);
      rho_i += p.mass[j] * w.w_i;
      if (j < m) p.rho[j] += mi * w.w_j;
    }
    if (i < m) p.rho[i] += rho_i;
  }, "density");
  par::for_each(m, [&](std::size_t i) { p.volume[i] = p.mass[i] / p.rho[i]; }, "density");
}

// One global smoothing length.
template <class K, int D>
void compute_density(Particles<D>& p, const PairLists& pl, const KernelAt<K, D>& kern, PairFactors& factors) {
  const double w0 = kern.W(0.0);
  sum_density(p, pl, factors, [w0](std::size_t) { return w0; }, [&kern](std::uint32_t) {
    return [k = kern](std::uint32_t, double r) {
      const double w = k.W(r);
      return PairKernel{w, w, k.dW_over_r(r)};
    };
  });
}

// Per-particle smoothing lengths p.h. `kernels` is scratch (one bound kernel per particle).
template <class K, int D>
void compute_density(Particles<D>& p, const PairLists& pl, std::vector<KernelAt<K, D>>& kernels, PairFactors& factors) {
  kernels.resize(p.size(), KernelAt<K, D>(1.0));
  par::for_each(p.size(), [&](std::size_t i) { kernels[i] = KernelAt<K, D>(p.h[i]); }, "density");
  sum_density(p, pl, factors, [&kernels](std::size_t i) { return kernels[i].W(0.0); },
              [&kernels](std::uint32_t i) {
                return [ki = kernels[i], all = kernels.data()](std::uint32_t j, double r) {
                  const KernelAt<K, D>& kj = all[j];
                  // One division per pair: (dW_i/dr + dW_j/dr) / (2 r); w'(0) = 0, so coincident particles get 0.
                  return PairKernel{ki.W(r), kj.W(r), r > 0 ? (ki.dW_dr(r) + kj.dW_dr(r)) / (2.0 * r) : 0.0};
                };
              });
}

}  // namespace sphdisk
