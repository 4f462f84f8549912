#pragma once
// The AVX-512 bodies of the pair-list sums (list_sums.hpp), for list_sums.cpp's dispatch, and the
// pieces the 2D and 3D bodies share. Each body gives the scalar loop's terms in its order, so the
// same bits (tests `same_bits_any_vector_path`, `ListSums.*`). Their files are compiled with
// -ffp-contract=off (src/CMakeLists.txt): a product added to a sum must not be fused in one path
// and not the other.
#include "core/vector_isa.hpp"  // (defines SPHDISK_X86_VECTOR_DISPATCH where these bodies exist)
#ifdef SPHDISK_X86_VECTOR_DISPATCH
#include <immintrin.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "core/avx512_norms.hpp"
#include "core/avx512_partner_loads.hpp"
#include "physics/list_sums.hpp"

namespace sphdisk::list_avx512 {

// Intrinsics in their maskz forms with all lanes set where GCC 12 warns that the plain forms'
// undefined source may be used.

static_assert(sizeof(Vec<2>) == 2 * sizeof(double), "positions and velocities are read as interleaved x, y");
static_assert(offsetof(GradientSums<2>, M) == 4 * sizeof(double), "a particle's eq. 8 and moment sums are its first eight doubles");
static_assert(offsetof(GradientMoments<2>, M) == 4 * sizeof(double) && sizeof(GradientMoments<2>) == 8 * sizeof(double),
              "the kept eq. 8 and moment sums are eight doubles");

// Rows r[c] (component c of eight pairs) to columns r[k] (the eight components of pair k).
[[gnu::target("avx512f"), gnu::always_inline]] inline void transpose8(__m512d r[8]) {
  __m512d t[8], u[8];
  for (int k = 0; k < 8; k += 2) {
    t[k] = _mm512_maskz_unpacklo_pd(0xFF, r[k], r[k + 1]);
    t[k + 1] = _mm512_maskz_unpackhi_pd(0xFF, r[k], r[k + 1]);
  }
  for (int k = 0; k < 8; k += 4) {
    u[k] = _mm512_maskz_shuffle_f64x2(0xFF, t[k], t[k + 2], 0x88);          // pairs 0 and 4
    u[k + 1] = _mm512_maskz_shuffle_f64x2(0xFF, t[k], t[k + 2], 0xDD);      // pairs 2 and 6
    u[k + 2] = _mm512_maskz_shuffle_f64x2(0xFF, t[k + 1], t[k + 3], 0x88);  // pairs 1 and 5
    u[k + 3] = _mm512_maskz_shuffle_f64x2(0xFF, t[k + 1], t[k + 3], 0xDD);  // pairs 3 and 7
  }
  r[0] = _mm512_maskz_shuffle_f64x2(0xFF, u[0], u[4], 0x88);
  r[4] = _mm512_maskz_shuffle_f64x2(0xFF, u[0], u[4], 0xDD);
  r[2] = _mm512_maskz_shuffle_f64x2(0xFF, u[1], u[5], 0x88);
  r[6] = _mm512_maskz_shuffle_f64x2(0xFF, u[1], u[5], 0xDD);
  r[1] = _mm512_maskz_shuffle_f64x2(0xFF, u[2], u[6], 0x88);
  r[5] = _mm512_maskz_shuffle_f64x2(0xFF, u[2], u[6], 0xDD);
  r[3] = _mm512_maskz_shuffle_f64x2(0xFF, u[3], u[7], 0x88);
  r[7] = _mm512_maskz_shuffle_f64x2(0xFF, u[3], u[7], 0xDD);
}

// The eight lanes of sums totalled as lane_total totals them (lane_sums.hpp): the upper half added
// to the lower, then again, then the two.
[[gnu::target("avx512f"), gnu::always_inline]] inline double lane_total(__m512d v) {
  const __m256d four = _mm256_add_pd(_mm512_maskz_extractf64x4_pd(0xFF, v, 0), _mm512_maskz_extractf64x4_pd(0xFF, v, 1));
  const __m128d two = _mm_add_pd(_mm256_castpd256_pd128(four), _mm256_extractf128_pd(four, 1));
  return _mm_cvtsd_f64(two) + _mm_cvtsd_f64(_mm_unpackhi_pd(two, two));
}

// -x exactly (the sign bit flipped; 0 - x would turn -0 into +0).
[[gnu::target("avx512f"), gnu::always_inline]] inline __m512d negated(__m512d x) {
  return _mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(x), _mm512_set1_epi64(INT64_MIN)));
}

// The partners of one round (up to eight): their indices and kernel-gradient factors (0 in the
// lanes past the list's end).
struct Round {
  avx512::Round8 j;
  __m512d f;
};

[[gnu::target("avx512f,avx512vl"), gnu::always_inline]] inline Round load_round(const std::uint32_t* js, const float* F,
                                                                                std::size_t q, std::size_t n) {
  const std::size_t count = std::min<std::size_t>(8, n - q);
  return {avx512::round8(js + q, count), _mm512_maskz_cvtps_pd(0xFF, avx512::load_f32(F + q, count))};
}

static_assert(sizeof(Vec<3>) == 3 * sizeof(double), "positions and velocities are read as x, y, z");
static_assert(offsetof(GradientSums<3>, M) == 9 * sizeof(double), "a particle's eq. 8 and moment sums are its first 18 doubles");
static_assert(offsetof(GradientMoments<3>, M) == 9 * sizeof(double) && sizeof(GradientMoments<3>) == 18 * sizeof(double),
              "the kept eq. 8 and moment sums are 18 doubles");


// x, y, z at p in lanes 0-2, 0 in lane 3 (two loads, no masked load).
[[gnu::target("avx512f,avx512vl"), gnu::always_inline]] inline __m256d load_xyz(const double* p) {
  return _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p)), _mm_load_sd(p + 2), 1);
}

// Lanes 0 and 1.
[[gnu::target("avx512f"), gnu::always_inline]] inline __m128d low_pair(__m512d x) {
  return _mm256_castpd256_pd128(_mm512_maskz_extractf64x4_pd(0xFF, x, 0));
}

// The bodies (list_sums_avx512_2d.cpp, list_sums_avx512_3d.cpp).
[[gnu::target("avx512f,avx512vl")]] void gradient_list_avx512(const GradientListData<2>& d, std::uint32_t i,
                                                              const std::uint32_t* js, const float* F, std::size_t n,
                                                              GradientSums<2>& sum_i);
[[gnu::target("avx512f,avx512vl")]] void gradient_list_avx512(const GradientListData<3>& d, std::uint32_t i,
                                                              const std::uint32_t* js, const float* F, std::size_t n,
                                                              GradientSums<3>& sum_i);
[[gnu::target("avx512f,avx512vl")]] void scatter_list_avx512(const ScatterListData<2>& d, std::uint32_t i,
                                                             const std::uint32_t* js, std::size_t n, double& sum_i);
#ifndef SPHDISK_SINGLE_PRECISION_FIELDS  // (stresses stored as double)
[[gnu::target("avx512f,avx512vl")]] void force_list_avx512(const ForceListData<2>& d, std::uint32_t i, const std::uint32_t* js,
                                                           const float* F, std::size_t n, Vec<2>& ai);
template <bool Pressure>
[[gnu::target("avx512f,avx512vl")]] void consistent_force_list_avx512(const ForceListData<2>& d, std::uint32_t i,
                                                                      const std::uint32_t* js, const float* F, std::size_t n,
                                                                      Vec<2>& ai, double& du_i);
template <bool ArtificialViscosity>
[[gnu::target("avx512f,avx512vl")]] void pressure_force_list_avx512(const ForceListData<3>& d, std::uint32_t i,
                                                                    const std::uint32_t* js, const float* F, std::size_t n,
                                                                    Vec<3>& ai, double& du_i);
[[gnu::target("avx512f,avx512vl")]] void consistent_pressure_force_list_avx512(const ForceListData<3>& d, std::uint32_t i,
                                                                               const std::uint32_t* js, const float* F,
                                                                               std::size_t n, Vec<3>& ai, double& du_i);
#endif

}  // namespace sphdisk::list_avx512

#endif
