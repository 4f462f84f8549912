#pragma once
// Squared norms of eight 2D or 3D vectors given component by component, formed as norm2
// (core/vec.hpp) forms them: the squares fused where the build has FMA, plain products and sums
// otherwise, so that the AVX-512 loops (neighbours/candidate_scan.cpp, physics/list_sums_avx512_*.cpp) give
// the scalar code's bits.
#include "core/vector_isa.hpp"

#ifdef SPHDISK_X86_VECTOR_DISPATCH
#include <immintrin.h>

namespace sphdisk::avx512 {

[[gnu::target("avx512f"), gnu::always_inline]] inline __m512d squared_norms(__m512d x, __m512d y) {
#ifdef __FMA__
  return _mm512_fmadd_pd(y, y, _mm512_mul_pd(x, x));
#else
  return _mm512_add_pd(_mm512_mul_pd(x, x), _mm512_mul_pd(y, y));
#endif
}

[[gnu::target("avx512f"), gnu::always_inline]] inline __m512d squared_norms(__m512d x, __m512d y, __m512d z) {
#ifdef __FMA__
  return _mm512_fmadd_pd(z, z, _mm512_fmadd_pd(y, y, _mm512_mul_pd(x, x)));
#else
  return _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(x, x), _mm512_mul_pd(y, y)), _mm512_mul_pd(z, z));
#endif
}

}  // namespace sphdisk::avx512
#endif
