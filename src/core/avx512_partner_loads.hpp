#pragma once
// Eight partners' records read by index into one vector per component, without gather
// instructions, for the AVX-512 list loops (physics/list_sums_avx512_2d.cpp and _3d.cpp, list_factors.cpp,
// neighbours/candidate_scan.cpp). Gathers are slow on AMD's AVX-512 CPUs (the force list loop
// with gathers ran slower there than its AVX2 form, which loads each partner's record and
// transposes), and so are masked loads, so these loops mask only the last, partial round
// (docs/performance.md, "Vector loops (AVX-512 and AVX2)"). Loads and shuffles give the same
// values as gathers, so the bits do not change.
#include "core/vector_isa.hpp"

#ifdef SPHDISK_X86_VECTOR_DISPATCH
#include <immintrin.h>

#include <cstddef>
#include <cstdint>

namespace sphdisk::avx512 {

// The partner indices of one round of up to eight. A partial round repeats its first partner in
// the missing lanes: a record that exists, whose values the caller never uses.
struct Round8 {
  std::size_t j[8];
};

[[gnu::always_inline]] inline Round8 round8(const std::uint32_t* js, std::size_t count) {
  Round8 r;
  for (std::size_t k = 0; k < 8; ++k) r.j[k] = js[k < count ? k : 0];
  return r;
}

// Eight entries from `at`, of which the first `count` are wanted (0 in the others): a masked load
// only when count < 8 (count 0 reads nothing).
[[gnu::target("avx512f,avx512vl"), gnu::always_inline]] inline __m256i load_u32(const std::uint32_t* at, std::size_t count) {
  if (count >= 8) return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(at));
  return _mm256_maskz_loadu_epi32(static_cast<__mmask8>((1u << count) - 1u), at);
}
[[gnu::target("avx512f,avx512vl"), gnu::always_inline]] inline __m256 load_f32(const float* at, std::size_t count) {
  if (count >= 8) return _mm256_loadu_ps(at);
  return _mm256_maskz_loadu_ps(static_cast<__mmask8>((1u << count) - 1u), at);
}
[[gnu::target("avx512f"), gnu::always_inline]] inline __m512d load_f64(const double* at, std::size_t count) {
  if (count >= 8) return _mm512_loadu_pd(at);
  return _mm512_maskz_loadu_pd(static_cast<__mmask8>((1u << count) - 1u), at);
}

// lo and hi as one vector (the mask form with lo as its source: the plain one passes an undefined
// source that GCC 12 warns about).
[[gnu::target("avx512f"), gnu::always_inline]] inline __m512d joined(__m256d lo, __m256d hi) {
  const __m512d wide = _mm512_castpd256_pd512(lo);
  return _mm512_mask_insertf64x4(wide, 0xFF, wide, hi, 1);
}

// The records of partners k and k + 1, side by side (two doubles each; four each).
[[gnu::target("avx512f"), gnu::always_inline]] inline __m256d two_pairs(const double* base, const Round8& r, std::size_t k) {
  return _mm256_set_m128d(_mm_loadu_pd(base + 2 * r.j[k + 1]), _mm_loadu_pd(base + 2 * r.j[k]));
}
[[gnu::target("avx512f"), gnu::always_inline]] inline __m512d two_quads(const double* base, const Round8& r, std::size_t k) {
  return joined(_mm256_loadu_pd(base + 4 * r.j[k]), _mm256_loadu_pd(base + 4 * r.j[k + 1]));
}

// Records of two doubles at base + 2 j: component 0 of the eight partners in c0, component 1 in c1.
[[gnu::target("avx512f"), gnu::always_inline]] inline void load_pairs(const double* base, const Round8& r, __m512d& c0,
                                                                       __m512d& c1) {
  const __m512d a = joined(two_pairs(base, r, 0), two_pairs(base, r, 2));  // x0 y0 ... y3
  const __m512d b = joined(two_pairs(base, r, 4), two_pairs(base, r, 6));  // partners 4-7
  c0 = _mm512_permutex2var_pd(a, _mm512_setr_epi64(0, 2, 4, 6, 8, 10, 12, 14), b);
  c1 = _mm512_permutex2var_pd(a, _mm512_setr_epi64(1, 3, 5, 7, 9, 11, 13, 15), b);
}

// Records of four doubles at base + 4 j: component c of the eight partners in c4[c].
[[gnu::target("avx512f"), gnu::always_inline]] inline void load_quads(const double* base, const Round8& r, __m512d c4[4]) {
  const __m512d r01 = two_quads(base, r, 0), r23 = two_quads(base, r, 2), r45 = two_quads(base, r, 4),
                r67 = two_quads(base, r, 6);
  // Within 128-bit lanes: lo = components 0 and 2, hi = 1 and 3, of partners (0, 2) and (1, 3) ...
  const __m512d lo0 = _mm512_maskz_unpacklo_pd(0xFF, r01, r23), hi0 = _mm512_maskz_unpackhi_pd(0xFF, r01, r23);
  const __m512d lo1 = _mm512_maskz_unpacklo_pd(0xFF, r45, r67), hi1 = _mm512_maskz_unpackhi_pd(0xFF, r45, r67);
  // ... lanes of lo0: (p0 p2)[0], (p0 p2)[2], (p1 p3)[0], (p1 p3)[2]; put back in partner order.
  const __m512i even = _mm512_setr_epi64(0, 4, 1, 5, 8, 12, 9, 13), odd = _mm512_setr_epi64(2, 6, 3, 7, 10, 14, 11, 15);
  c4[0] = _mm512_permutex2var_pd(lo0, even, lo1);
  c4[2] = _mm512_permutex2var_pd(lo0, odd, lo1);
  c4[1] = _mm512_permutex2var_pd(hi0, even, hi1);
  c4[3] = _mm512_permutex2var_pd(hi0, odd, hi1);
}

// Single doubles at base + j.
[[gnu::target("avx512f"), gnu::always_inline]] inline __m512d load_singles(const double* base, const Round8& r) {
  return _mm512_setr_pd(base[r.j[0]], base[r.j[1]], base[r.j[2]], base[r.j[3]], base[r.j[4]], base[r.j[5]], base[r.j[6]],
                        base[r.j[7]]);
}

// Single 32-bit entries at base + j.
[[gnu::target("avx512f"), gnu::always_inline]] inline __m256i load_u32_singles(const std::uint32_t* base, const Round8& r) {
  return _mm256_setr_epi32(static_cast<int>(base[r.j[0]]), static_cast<int>(base[r.j[1]]), static_cast<int>(base[r.j[2]]),
                           static_cast<int>(base[r.j[3]]), static_cast<int>(base[r.j[4]]), static_cast<int>(base[r.j[5]]),
                           static_cast<int>(base[r.j[6]]), static_cast<int>(base[r.j[7]]));
}

}  // namespace sphdisk::avx512
#endif
