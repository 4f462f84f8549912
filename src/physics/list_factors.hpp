#pragma once
// The kernel-gradient factors F_ij of one half list with variable h (pair_factors.hpp; the pair
// average of density.hpp's pair_average_factor), formed by the first pair loop that reads them
// (StoredPairsFormingFactors, pair_lists.hpp). The partners' squared distances and kernel slopes are
// gathered first, so that the loop of square roots, kernel slopes and divisions runs on contiguous
// data and vectorises. In 2D on CPUs with AVX-512 (asked at run time, core/vector_isa.hpp) the
// gathers take eight partners at a time and the loop runs eight-wide; with AVX2 the same code as the
// baseline runs four-wide; the same operations on each element, without floating-point contraction
// (list_factors.cpp), so the same bits on every path. The factors made from h (factors_from_h) are
// dispatched so in 3D as well.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "core/snug_resize.hpp"
#include "core/vec.hpp"
#include "physics/kernels.hpp"
#include "physics/pair_factors.hpp"

namespace sphdisk {

// (always_inline: list_factors.cpp compiles it for AVX2 too.)
template <class K, int D>
[[gnu::always_inline]] inline void form_list_factors_scalar(const Vec<D>* pos, const KernelSlope* slopes, std::uint32_t i,
                              std::span<const std::uint32_t> js, std::span<float> factors) {
  thread_local std::vector<double> r2_buffer;
  thread_local std::vector<KernelSlope> sj_buffer;
  double* r2 = scratch_for(r2_buffer, js.size());
  KernelSlope* sj = scratch_for(sj_buffer, js.size());
  const Vec<D> xi = pos[i];
  for (std::size_t q = 0; q < js.size(); ++q) {
    r2[q] = norm2(xi - pos[js[q]]);
    sj[q] = slopes[js[q]];
  }
  const KernelSlope si = slopes[i];
  for (std::size_t q = 0; q < js.size(); ++q)
    factors[q] = static_cast<float>(pair_average_factor<K>(si, sj[q], std::sqrt(r2[q])));
}

// 2D: dispatched (list_factors.cpp; instantiated for the kernels of kernels.hpp).
template <class K>
void form_list_factors(const Vec<2>* pos, const KernelSlope* slopes, std::uint32_t i, std::span<const std::uint32_t> js,
                       std::span<float> factors);

// The factors of the pairs (i, js[q]) at known squared distances r2[q], each partner's kernel slope
// made from its h as slope_of(KernelAt) makes it (the same values as form_list_factors' from slopes
// bound from the same h): for the pair loops that search their pairs anew (neighbours/pair_scan.hpp)
// and keep no per-particle slopes. The partners' h are gathered first, so that the loop of
// divisions and square roots runs on contiguous data; it runs over whole vectors of eight (the
// lanes past the list's end on i's own h and stale squared distances: r2 needs room for
// js.size() + 8 finite values) into scratch, then the list's factors are copied out.
template <class K, int D>
[[gnu::always_inline]] inline void factors_from_h_scalar(double h_i, const double* h, std::span<const std::uint32_t> js,
                                                         const double* r2, std::span<float> factors) {
  thread_local std::vector<double> h_buffer;
  thread_local std::vector<float> factor_buffer;
  const std::size_t n = js.size(), whole = (n + 7) & ~std::size_t{7};
  double* hj = scratch_for(h_buffer, whole);
  float* F = scratch_for(factor_buffer, whole);
  for (std::size_t q = 0; q < n; ++q) hj[q] = h[js[q]];
  for (std::size_t q = n; q < whole; ++q) hj[q] = h_i;
  const KernelSlope si = slope_of(KernelAt<K, D>(h_i));
  for (std::size_t q = 0; q < whole; ++q)
    F[q] = static_cast<float>(pair_average_factor<K>(si, slope_of(KernelAt<K, D>(hj[q])), std::sqrt(r2[q])));
  std::copy_n(F, n, factors.data());
}

// 2D and 3D: dispatched (list_factors.cpp; instantiated for the kernels of kernels.hpp).
template <class K, int D>
void factors_from_h(double h_i, const double* h, std::span<const std::uint32_t> js, const double* r2,
                    std::span<float> factors);

// The second loop: on contiguous squared distances, so that it vectorises.
template <class K, int D>
[[gnu::always_inline]] inline void constant_h_kernels(const KernelAt<K, D>& kern, const double* r2, std::size_t n, double* w,
                                                      float* factors) {
  const KernelAt<K, D> k = kern;  // by value: stores to w and factors cannot alias it
  for (std::size_t q = 0; q < n; ++q) {
    const double r = std::sqrt(r2[q]);
    w[q] = k.W(r);
    factors[q] = static_cast<float>(k.dW_over_r(r));
  }
}

// With one global h (the density loop of density.hpp): the kernel values w[q] = W(r) and factors
// F[q] = dW/dr / r of the pairs (i, js[q]), r = |x_i - x_js[q]|, in two loops like the ones
// above: squared distances first, then square roots and kernels on contiguous data.
template <class K, int D>
[[gnu::always_inline]] inline void constant_h_list_scalar(const Vec<D>* pos, const KernelAt<K, D>& kern, std::uint32_t i,
                                                          std::span<const std::uint32_t> js, double* w, std::span<float> factors) {
  thread_local std::vector<double> r2_buffer;
  double* r2 = scratch_for(r2_buffer, js.size());
  const Vec<D> xi = pos[i];
  for (std::size_t q = 0; q < js.size(); ++q) r2[q] = norm2(xi - pos[js[q]]);
  constant_h_kernels(kern, r2, js.size(), w, factors.data());
}

// 2D: dispatched (list_factors.cpp); w has room for js.size() values.
template <class K>
void constant_h_list(const Vec<2>* pos, const KernelAt<K, 2>& kern, std::uint32_t i, std::span<const std::uint32_t> js,
                     double* w, std::span<float> factors);

// The same kernel values and factors of n pairs at known squared distances r2[q] (the density summed
// during the search, neighbours/tile_half_lists.hpp): constant_h_kernels, in 2D compiled eight-wide
// (AVX-512) or four-wide (AVX2) where the CPU allows (list_factors.cpp).
template <class K>
void kernels_at_distances(const KernelAt<K, 2>& kern, const double* r2, std::size_t n, double* w, float* factors);

template <class K>
void kernels_at_distances(const KernelAt<K, 3>& kern, const double* r2, std::size_t n, double* w, float* factors) {
  constant_h_kernels(kern, r2, n, w, factors);
}

template <class K>
void constant_h_list(const Vec<3>* pos, const KernelAt<K, 3>& kern, std::uint32_t i, std::span<const std::uint32_t> js,
                     double* w, std::span<float> factors) {
  constant_h_list_scalar<K, 3>(pos, kern, i, js, w, factors);
}

template <class K>
void form_list_factors(const Vec<3>* pos, const KernelSlope* slopes, std::uint32_t i, std::span<const std::uint32_t> js,
                       std::span<float> factors) {
  form_list_factors_scalar<K, 3>(pos, slopes, i, js, factors);
}

}  // namespace sphdisk
