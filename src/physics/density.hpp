#pragma once
// Density by summation (P98 eq. 4 with f = rho; docs/physics.md sec. 2), self term included:
//   rho_i = sum_j m_j W(|x_i - x_j|, h_i).
// In 2D rho is the surface density Sigma.
// With one global h the sum is a pair loop: each pair is visited once (pair_lists.hpp), its
// distance, both kernel values and its kernel-gradient factor dW(r, h)/dr / r (pair_factors.hpp) are
// computed once and serve both particles; where the lists are searched on the loops' schedule
// (neighbours/tile_half_lists.hpp) the search sums it on its way. With variable h the
// smoothing-length solve has summed rho already (smoothing_length.hpp), and the factors, the pair
// average of dW(r, h_i)/dr / r and dW(r, h_j)/dr / r (symmetric in i <-> j as momentum conservation
// needs), are formed by the first pair loop that reads them.
// Each pair's terms: density_term (pair_terms.hpp).
// The particle volume m/rho, the weight of every later pair sum (eqs. 6, 8), is stored with rho.
// Computed for the writable particles (pairs.writable(): all of them, or a process's own active
// particles when the rest are ghosts or inactive ones, which keep their values).
// Reads: pos, mass, h. Writes: rho, volume, pair factors (where the pairs store them).
#include <cmath>
#include <type_traits>
#include <vector>

#include "core/pair_source.hpp"
#include "core/particles.hpp"
#include "core/snug_resize.hpp"
#include "parallel/loops.hpp"
#include "physics/kernels.hpp"
#include "physics/list_factors.hpp"
#include "physics/pair_factors.hpp"
#include "physics/pair_terms.hpp"

namespace sphdisk {

// The volumes m/rho of the writable particles. With variable h this is all that is left of the
// density stage: rho_i came with h_i from the smoothing-length solve, and the pair factors
// (pair_average_factor below) are formed by the first pair loop that reads them
// (StoredPairsFormingFactors, pair_lists.hpp; rescanned pairs form them in every loop).
template <int D>
void set_volumes(Particles<D>& p, std::size_t writable) {
  par::for_each(writable, [&](std::size_t i) { p.volume[i] = p.mass[i] / p.rho[i]; }, "density");
}

// One global smoothing length: W(r, h) and the factor serve both particles of a pair. The sums of
// an evaluation, list by list: the self terms on construction, each half list's terms by add_list
// (i's own sum over the list in list order, then added to rho_i; each writable partner's term added
// to its rho as the pair comes), rho stored and the volumes set by finish. The lists come from a
// pair loop (compute_density) or from the search itself (density_while_searching).
template <class K, int D>
class ConstantHDensity {
 public:
  ConstantHDensity(Particles<D>& p, const KernelAt<K, D>& kern, std::size_t writable) : p_(p), kern_(kern), m_(writable) {
    if constexpr (!kDoubleRho) wide_.resize(p.size());  // here, not in add_list, which threads call at once
    const double self_W = kern.W(0.0);
    double* rho = sums();
    par::for_each(m_, [&](std::size_t i) { rho[i] = density_term(p_.mass[i], self_W); }, "density");
  }
  const KernelAt<K, D>& kernel() const { return kern_; }
  // The terms of i's half list js, w[q] = W(|x_i - x_js[q]|, h).
  void add_list(std::uint32_t i, std::span<const std::uint32_t> js, const double* w) const {
    double* rho = sums();
    const double mi = p_.mass[i];
    double rho_i = 0.0;
    for (std::size_t q = 0; q < js.size(); ++q) {
      const std::uint32_t j = js[q];
      rho_i += density_term(p_.mass[j], w[q]);
      if (j < m_) rho[j] += density_term(mi, w[q]);
    }
    if (i < m_) rho[i] += rho_i;
  }
  void finish() {
    if constexpr (!kDoubleRho) par::for_each(m_, [&](std::size_t i) { store(p_.rho[i], wide_[i]); }, "density");
    set_volumes(p_, m_);
  }

 private:
  // The sums in double: p.rho itself, or, where it is stored in single precision, a double copy
  // stored by finish.
  static constexpr bool kDoubleRho = std::is_same_v<decltype(Particles<D>::rho), std::vector<double>>;
  double* sums() const {
    if constexpr (kDoubleRho) return p_.rho.data();
    else return wide_.data();
  }

  Particles<D>& p_;
  const KernelAt<K, D> kern_;  // by value: stores to rho cannot alias it (it would be reloaded after each)
  std::size_t m_;
  mutable std::vector<double> wide_;  // (mutable: add_list is const, as the loops' bodies are)
};

// pairs: StoredPairs (pair_lists.hpp), ScannedPairs (pair_scan.hpp) or TiledPairs (tile_half_lists.hpp).
template <class K, int D, PairSource Pairs>
void compute_density(Particles<D>& p, const Pairs& pairs, const KernelAt<K, D>& kern) {
  pairs.prepare_factors();
  ConstantHDensity<K, D> sums(p, kern, pairs.writable());
  pairs.for_each_list([&](std::uint32_t i, std::span<const std::uint32_t> js, std::span<float> factors) {
    // The kernel values and factors of the list (list_factors.hpp: squared distances first, then
    // square roots and kernels on contiguous data, eight partners at a time where the CPU allows),
    // then the sums in list order.
    thread_local std::vector<double> w_buffer;
    double* w = scratch_for(w_buffer, js.size() + 8);
    constant_h_list<K>(p.pos.data(), sums.kernel(), i, js, w, factors);
    sums.add_list(i, js, w);
  }, FactorUse::Write, "density");
  sums.finish();
}

// The same sums during the search (neighbours/tile_half_lists.hpp: its visit): each list's kernel
// values and factors from the squared distances the search found, the same values as
// constant_h_list's (which forms the same squared distances), so the same bits as compute_density
// on the same lists.
template <class K, int D>
auto density_while_searching(ConstantHDensity<K, D>& sums) {
  return [&sums](std::uint32_t i, std::span<const std::uint32_t> js, std::span<const double> d2, std::span<float> factors) {
    thread_local std::vector<double> w_buffer;
    double* w = scratch_for(w_buffer, js.size());
    kernels_at_distances<K>(sums.kernel(), d2.data(), js.size(), w, factors.data());
    sums.add_list(i, js, w);
  };
}

// Each particle's kernel slope at its smoothing length p.h.
template <class K, int D>
void bind_kernel_slopes(const Particles<D>& p, std::vector<KernelSlope>& slopes) {
  grow_snug(slopes, p.size());  // (entries past p.size() are stale)
  par::for_each(p.size(), [&](std::size_t i) { slopes[i] = slope_of(KernelAt<K, D>(p.h[i])); }, "density");
}

}  // namespace sphdisk
