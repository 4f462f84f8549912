#pragma once
// The kernel-gradient factors F_ij of one half list with variable h (pair_factors.hpp; the pair
// average of density.hpp's pair_average_factor), formed by the first pair loop that reads them
// (StoredPairsFormingFactors, pair_lists.hpp). The partners' squared distances and kernel slopes are
// gathered first, so that the loop of square roots, kernel slopes and divisions runs on contiguous
// data and vectorises. In 2D on CPUs with AVX-512 (asked at run time, core/vector_isa.hpp) the
// gathers take eight partners at a time and the loop runs eight-wide; with AVX2 the same code as the
// baseline runs four-wide; the same operations on each element, without floating-point contraction
// (list_factors.cpp), so the same bits on every path.
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "core/snug_resize.hpp"
#include "core/vec.hpp"
#include "physics/density.hpp"

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

template <class K>
void form_list_factors(const Vec<3>* pos, const KernelSlope* slopes, std::uint32_t i, std::span<const std::uint32_t> js,
                       std::span<float> factors) {
  form_list_factors_scalar<K, 3>(pos, slopes, i, js, factors);
}

}  // namespace sphdisk
