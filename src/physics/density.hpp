#pragma once
// Density by summation (P98 eq. 4 with f = rho; physics.md sec. 2), self term included:
//   rho_i = sum_j m_j W(|x_i - x_j|, h_i).
// In 2D rho is the surface density Sigma.
// With one global h the sum is a pair loop: each pair is visited once (pair_lists.hpp), its
// distance, both kernel values and its kernel-gradient factor dW(r, h)/dr / r (pair_factors.hpp) are
// computed once and serve both particles. With variable h the smoothing-length solve has summed rho
// already (smoothing_length.hpp), and the factors, the pair average of dW(r, h_i)/dr / r and
// dW(r, h_j)/dr / r (symmetric in i <-> j as momentum conservation needs), are formed by the first
// pair loop that reads them.
// The particle volume m/rho, the weight of every later pair sum (eqs. 6, 8), is stored with rho.
// Computed for the writable particles (pairs.writable(): all of them, or a process's own active
// particles when the rest are ghosts or inactive ones, which keep their values).
// Reads: pos, mass, h. Writes: rho, volume, pair factors (where the pairs store them).
#include <cmath>
#include <type_traits>
#include <vector>

#include "core/particles.hpp"
#include "core/snug_resize.hpp"
#include "neighbours/pair_lists.hpp"
#include "parallel/loops.hpp"
#include "physics/kernels.hpp"
#include "physics/list_factors.hpp"
#include "physics/pair_factors.hpp"

namespace sphdisk {

// The volumes m/rho of the writable particles. With variable h this is all that is left of the
// density stage: rho_i came with h_i from the smoothing-length solve, and the pair factors
// (pair_average_factor below) are formed by the first pair loop that reads them
// (StoredPairsFormingFactors, pair_lists.hpp; rescanned pairs form them in every loop).
template <int D>
void set_volumes(Particles<D>& p, std::size_t writable) {
  par::for_each(writable, [&](std::size_t i) { p.volume[i] = p.mass[i] / p.rho[i]; }, "density");
}

// One global smoothing length: W(r, h) and the factor serve both particles of a pair.
// pairs: StoredPairs (pair_lists.hpp) or ScannedPairs (pair_scan.hpp).
template <class K, int D, class Pairs>
void compute_density(Particles<D>& p, const Pairs& pairs, const KernelAt<K, D>& kern) {
  pairs.prepare_factors();
  const std::size_t m = pairs.writable();
  const double self_W = kern.W(0.0);
  // The sums in double: p.rho itself, or, where it is stored in single precision, a double copy
  // stored at the end.
  std::vector<double> wide;
  std::vector<double>& rho = [&]() -> std::vector<double>& {
    if constexpr (std::is_same_v<decltype(p.rho), std::vector<double>>) {
      return p.rho;
    } else {
      wide.resize(p.size());
      return wide;
    }
  }();
  par::for_each(m, [&](std::size_t i) { rho[i] = p.mass[i] * self_W; }, "density");
  pairs.for_each_list([&](std::uint32_t i, std::span<const std::uint32_t> js, std::span<float> factors) {
    // The kernel by value: read through a reference it would be reloaded after every store to rho,
    // which may alias it.
    const KernelAt<K, D> k = kern;
    const double mi = p.mass[i];
    // The kernel values and factors of the list (list_factors.hpp: squared distances first, then
    // square roots and kernels on contiguous data, eight partners at a time where the CPU allows),
    // then the sums in list order.
    thread_local std::vector<double> w_buffer;
    double* w = scratch_for(w_buffer, js.size() + 8);
    constant_h_list<K>(p.pos.data(), k, i, js, w, factors);
    double rho_i = 0.0;
    for (std::size_t q = 0; q < js.size(); ++q) {
      const std::uint32_t j = js[q];
      rho_i += p.mass[j] * w[q];
      if (j < m) rho[j] += mi * w[q];
    }
    if (i < m) rho[i] += rho_i;
  }, FactorUse::Write, "density");
  if constexpr (!std::is_same_v<decltype(p.rho), std::vector<double>>)
    par::for_each(m, [&](std::size_t i) { store(p.rho[i], rho[i]); }, "density");
  set_volumes(p, m);
}

// Each particle's kernel slope at its smoothing length p.h.
template <class K, int D>
void bind_kernel_slopes(const Particles<D>& p, std::vector<KernelSlope>& slopes) {
  grow_snug(slopes, p.size());  // (entries past p.size() are stale)
  par::for_each(p.size(), [&](std::size_t i) { slopes[i] = slope_of(KernelAt<K, D>(p.h[i])); }, "density");
}

}  // namespace sphdisk
