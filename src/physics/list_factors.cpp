#include "physics/list_factors.hpp"

#include <algorithm>

#include "core/avx512_partner_loads.hpp"
#include "core/vector_isa.hpp"
#include "physics/kernels.hpp"

// Compiled with -ffp-contract=off (src/CMakeLists.txt): the AVX-512 build of the factor loop could
// fuse products into sums where the baseline one cannot, and all paths must give the same bits.
#ifdef SPHDISK_X86_VECTOR_DISPATCH
#include <immintrin.h>
#endif

namespace sphdisk {

namespace {

#ifdef SPHDISK_X86_VECTOR_DISPATCH

// dx^2 + dy^2 as norm2 forms it (core/vec.hpp), so that every path gives the same bits.
[[gnu::target("avx512f"), gnu::always_inline]] inline __m512d squared_distance(__m512d dx, __m512d dy) {
#ifdef __FMA__
  return _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dx, dx));  // as norm2 with FMA
#else
  return _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy));
#endif
}

// Eight partners per round: positions and kernel slopes loaded, squared distances formed as norm2
// does (core/vec.hpp), all stored contiguously; then the factor loop of the scalar path on them,
// compiled eight-wide here.
template <class K>
[[gnu::target("avx512f,avx512vl")]] void form_avx512(const Vec<2>* pos, const KernelSlope* slopes, std::uint32_t i,
                                                     std::span<const std::uint32_t> js, std::span<float> factors) {
  static_assert(sizeof(Vec<2>) == 2 * sizeof(double) && sizeof(KernelSlope) == 2 * sizeof(double),
                "positions and slopes are read as pairs of doubles");
  thread_local std::vector<double> r2_buffer, inv_h_buffer, dw_norm_buffer;
  const std::size_t n = js.size();
  double* r2 = scratch_for(r2_buffer, n + 8);  // whole vectors of eight
  double* inv_h = scratch_for(inv_h_buffer, n + 8);
  double* dw_norm = scratch_for(dw_norm_buffer, n + 8);
  const double* xs = reinterpret_cast<const double*>(pos);
  const double* ss = reinterpret_cast<const double*>(slopes);
  const __m512d xi = _mm512_set1_pd(pos[i][0]), yi = _mm512_set1_pd(pos[i][1]);
  for (std::size_t q = 0; q < n; q += 8) {
    const avx512::Round8 j = avx512::round8(js.data() + q, std::min<std::size_t>(8, n - q));
    __m512d xj, yj, inv_hj, dw_normj;
    avx512::load_pairs(xs, j, xj, yj);
    avx512::load_pairs(ss, j, inv_hj, dw_normj);
    _mm512_storeu_pd(r2 + q, squared_distance(_mm512_sub_pd(xi, xj), _mm512_sub_pd(yi, yj)));
    _mm512_storeu_pd(inv_h + q, inv_hj);
    _mm512_storeu_pd(dw_norm + q, dw_normj);
  }
  // Whole vectors here too (the lanes past the list's end repeat its first partner, avx512::round8),
  // into scratch: a scalar remainder loop for the last n % 8 partners would wait on its divisions.
  // The list's own n factors are then copied out.
  thread_local std::vector<float> factor_buffer;
  const std::size_t whole = (n + 7) & ~std::size_t{7};
  float* F = scratch_for(factor_buffer, whole);
  const KernelSlope si = slopes[i];
  for (std::size_t q = 0; q < whole; ++q)
    F[q] = static_cast<float>(pair_average_factor<K>(si, KernelSlope{inv_h[q], dw_norm[q]}, std::sqrt(r2[q])));
  std::copy_n(F, n, factors.data());
}

// One global h: eight partners' positions per round, squared distances formed as norm2 does, then
// the kernel loop of the scalar path on them, compiled eight-wide here.
template <class K>
[[gnu::target("avx512f,avx512vl")]] void constant_h_avx512(const Vec<2>* pos, const KernelAt<K, 2>& kern, std::uint32_t i,
                                                           std::span<const std::uint32_t> js, double* w,
                                                           std::span<float> factors) {
  thread_local std::vector<double> r2_buffer;
  const std::size_t n = js.size();
  double* r2 = scratch_for(r2_buffer, n + 8);  // whole vectors of eight
  const double* xs = reinterpret_cast<const double*>(pos);
  const __m512d xi = _mm512_set1_pd(pos[i][0]), yi = _mm512_set1_pd(pos[i][1]);
  for (std::size_t q = 0; q < n; q += 8) {
    const avx512::Round8 j = avx512::round8(js.data() + q, std::min<std::size_t>(8, n - q));
    __m512d xj, yj;
    avx512::load_pairs(xs, j, xj, yj);
    _mm512_storeu_pd(r2 + q, squared_distance(_mm512_sub_pd(xi, xj), _mm512_sub_pd(yi, yj)));
  }
  constant_h_kernels(kern, r2, n, w, factors.data());
}

// The baseline code compiled for AVX2: the loop of square roots and divisions four-wide.
template <class K>
[[gnu::target("avx2")]] void form_avx2(const Vec<2>* pos, const KernelSlope* slopes, std::uint32_t i,
                                       std::span<const std::uint32_t> js, std::span<float> factors) {
  form_list_factors_scalar<K, 2>(pos, slopes, i, js, factors);
}

template <class K>
[[gnu::target("avx2")]] void constant_h_avx2(const Vec<2>* pos, const KernelAt<K, 2>& kern, std::uint32_t i,
                                             std::span<const std::uint32_t> js, double* w, std::span<float> factors) {
  constant_h_list_scalar<K, 2>(pos, kern, i, js, w, factors);
}

template <class K>
[[gnu::target("avx512f,avx512vl")]] void kernels_avx512(const KernelAt<K, 2>& kern, const double* r2, std::size_t n,
                                                        double* w, float* factors) {
  constant_h_kernels(kern, r2, n, w, factors);
}

template <class K>
[[gnu::target("avx2")]] void kernels_avx2(const KernelAt<K, 2>& kern, const double* r2, std::size_t n, double* w,
                                          float* factors) {
  constant_h_kernels(kern, r2, n, w, factors);
}

template <class K, int D>
[[gnu::target("avx512f,avx512vl")]] void factors_from_h_avx512(double h_i, const double* h, std::span<const std::uint32_t> js,
                                                               const double* r2, std::span<float> factors) {
  factors_from_h_scalar<K, D>(h_i, h, js, r2, factors);
}

template <class K, int D>
[[gnu::target("avx2")]] void factors_from_h_avx2(double h_i, const double* h, std::span<const std::uint32_t> js,
                                                 const double* r2, std::span<float> factors) {
  factors_from_h_scalar<K, D>(h_i, h, js, r2, factors);
}

#endif

}  // namespace

template <class K>
void form_list_factors(const Vec<2>* pos, const KernelSlope* slopes, std::uint32_t i, std::span<const std::uint32_t> js,
                       std::span<float> factors) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  switch (vector_isa()) {
    case VectorIsa::avx512: return form_avx512<K>(pos, slopes, i, js, factors);
    case VectorIsa::avx2: return form_avx2<K>(pos, slopes, i, js, factors);
    case VectorIsa::baseline: break;
  }
#endif
  form_list_factors_scalar<K, 2>(pos, slopes, i, js, factors);
}

// Factors from h: the same loop compiled eight-wide (AVX-512) or four-wide (AVX2), in 2D and 3D
// alike (only the kernel's normalisation differs).
template <class K, int D>
void factors_from_h(double h_i, const double* h, std::span<const std::uint32_t> js, const double* r2,
                    std::span<float> factors) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  switch (vector_isa()) {
    case VectorIsa::avx512: return factors_from_h_avx512<K, D>(h_i, h, js, r2, factors);
    case VectorIsa::avx2: return factors_from_h_avx2<K, D>(h_i, h, js, r2, factors);
    case VectorIsa::baseline: break;
  }
#endif
  factors_from_h_scalar<K, D>(h_i, h, js, r2, factors);
}

template <class K>
void kernels_at_distances(const KernelAt<K, 2>& kern, const double* r2, std::size_t n, double* w, float* factors) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  switch (vector_isa()) {
    case VectorIsa::avx512: return kernels_avx512<K>(kern, r2, n, w, factors);
    case VectorIsa::avx2: return kernels_avx2<K>(kern, r2, n, w, factors);
    case VectorIsa::baseline: break;
  }
#endif
  constant_h_kernels(kern, r2, n, w, factors);
}

// The same for one global h.
template <class K>
void constant_h_list(const Vec<2>* pos, const KernelAt<K, 2>& kern, std::uint32_t i, std::span<const std::uint32_t> js,
                     double* w, std::span<float> factors) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  switch (vector_isa()) {
    case VectorIsa::avx512: return constant_h_avx512<K>(pos, kern, i, js, w, factors);
    case VectorIsa::avx2: return constant_h_avx2<K>(pos, kern, i, js, w, factors);
    case VectorIsa::baseline: break;
  }
#endif
  constant_h_list_scalar<K, 2>(pos, kern, i, js, w, factors);
}

template void form_list_factors<CubicSpline>(const Vec<2>*, const KernelSlope*, std::uint32_t, std::span<const std::uint32_t>,
                                             std::span<float>);
template void form_list_factors<WendlandC2>(const Vec<2>*, const KernelSlope*, std::uint32_t, std::span<const std::uint32_t>,
                                            std::span<float>);
template void form_list_factors<WendlandC4>(const Vec<2>*, const KernelSlope*, std::uint32_t, std::span<const std::uint32_t>,
                                            std::span<float>);

template void constant_h_list<CubicSpline>(const Vec<2>*, const KernelAt<CubicSpline, 2>&, std::uint32_t,
                                           std::span<const std::uint32_t>, double*, std::span<float>);
template void constant_h_list<WendlandC2>(const Vec<2>*, const KernelAt<WendlandC2, 2>&, std::uint32_t,
                                          std::span<const std::uint32_t>, double*, std::span<float>);
template void constant_h_list<WendlandC4>(const Vec<2>*, const KernelAt<WendlandC4, 2>&, std::uint32_t,
                                          std::span<const std::uint32_t>, double*, std::span<float>);

template void factors_from_h<CubicSpline, 2>(double, const double*, std::span<const std::uint32_t>, const double*,
                                             std::span<float>);
template void factors_from_h<WendlandC2, 2>(double, const double*, std::span<const std::uint32_t>, const double*,
                                            std::span<float>);
template void factors_from_h<WendlandC4, 2>(double, const double*, std::span<const std::uint32_t>, const double*,
                                            std::span<float>);
template void factors_from_h<CubicSpline, 3>(double, const double*, std::span<const std::uint32_t>, const double*,
                                             std::span<float>);
template void factors_from_h<WendlandC2, 3>(double, const double*, std::span<const std::uint32_t>, const double*,
                                            std::span<float>);
template void factors_from_h<WendlandC4, 3>(double, const double*, std::span<const std::uint32_t>, const double*,
                                            std::span<float>);

template void kernels_at_distances<CubicSpline>(const KernelAt<CubicSpline, 2>&, const double*, std::size_t, double*, float*);
template void kernels_at_distances<WendlandC2>(const KernelAt<WendlandC2, 2>&, const double*, std::size_t, double*, float*);
template void kernels_at_distances<WendlandC4>(const KernelAt<WendlandC4, 2>&, const double*, std::size_t, double*, float*);

}  // namespace sphdisk
