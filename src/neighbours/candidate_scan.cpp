#include "neighbours/candidate_scan.hpp"

#include <algorithm>

#include "core/avx512_norms.hpp"
#include "core/avx512_partner_loads.hpp"
#include "core/vector_isa.hpp"

// Compiled with -ffp-contract=off (src/CMakeLists.txt): a product added to another must not be
// fused in one path and not the other, or the two would disagree on candidates at the radius.
#ifdef SPHDISK_X86_VECTOR_DISPATCH
#include <immintrin.h>
#endif

namespace sphdisk {

namespace {

// Entries k0..n-1 of idx kept behind the first `kept`, in place; returns the new count.
std::size_t keep_from(std::uint32_t* idx, const double* d2, std::size_t k0, std::size_t n, std::size_t kept, double r2) {
  for (std::size_t k = k0; k < n; ++k) {
    idx[kept] = idx[k];
    kept += static_cast<std::size_t>(d2[k] < r2);
  }
  return kept;
}

#ifdef SPHDISK_X86_VECTOR_DISPATCH

// The squared distances from x of eight consecutive positions at `at` (the first m loaded: whole
// vectors, or only m entries with masked loads), formed as norm2 forms them. 2D: x, y interleaved,
// two vectors split by permutes.
[[gnu::target("avx512f"), gnu::always_inline]] inline __m512d squared_distances(const double* at, unsigned m, const Vec<2>& x) {
  const __m512i even = _mm512_setr_epi64(0, 2, 4, 6, 8, 10, 12, 14), odd = _mm512_setr_epi64(1, 3, 5, 7, 9, 11, 13, 15);
  const __m512d a = avx512::load_f64(at, 2 * std::min(m, 4u));  // 2 m doubles: up to eight in a, the rest in b
  const __m512d b = avx512::load_f64(at + 8, m > 4 ? 2 * (m - 4) : 0);
  const __m512d dx = _mm512_sub_pd(_mm512_permutex2var_pd(a, even, b), _mm512_set1_pd(x[0]));
  const __m512d dy = _mm512_sub_pd(_mm512_permutex2var_pd(a, odd, b), _mm512_set1_pd(x[1]));
  return avx512::squared_norms(dx, dy);
}

// 3D: x, y, z interleaved, three vectors; component c of entry k is double 3k + c, entries 0-5 (x)
// or 0-4 (y, z) in the first two vectors, the rest in the third (indices 8 + 0..7 in the second
// permute).
[[gnu::target("avx512f"), gnu::always_inline]] inline __m512d squared_distances(const double* at, unsigned m, const Vec<3>& x) {
  const __m512i x_ab = _mm512_setr_epi64(0, 3, 6, 9, 12, 15, 0, 0), x_c = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 10, 13);
  const __m512i y_ab = _mm512_setr_epi64(1, 4, 7, 10, 13, 0, 0, 0), y_c = _mm512_setr_epi64(0, 1, 2, 3, 4, 8, 11, 14);
  const __m512i z_ab = _mm512_setr_epi64(2, 5, 8, 11, 14, 0, 0, 0), z_c = _mm512_setr_epi64(0, 1, 2, 3, 4, 9, 12, 15);
  const unsigned doubles = 3 * m;
  const __m512d a = avx512::load_f64(at, std::min(doubles, 8u));
  const __m512d b = avx512::load_f64(at + 8, doubles > 8 ? std::min(doubles - 8, 8u) : 0);
  const __m512d c = avx512::load_f64(at + 16, doubles > 16 ? doubles - 16 : 0);
  const __m512d dx = _mm512_sub_pd(_mm512_permutex2var_pd(_mm512_permutex2var_pd(a, x_ab, b), x_c, c), _mm512_set1_pd(x[0]));
  const __m512d dy = _mm512_sub_pd(_mm512_permutex2var_pd(_mm512_permutex2var_pd(a, y_ab, b), y_c, c), _mm512_set1_pd(x[1]));
  const __m512d dz = _mm512_sub_pd(_mm512_permutex2var_pd(_mm512_permutex2var_pd(a, z_ab, b), z_c, c), _mm512_set1_pd(x[2]));
  return avx512::squared_norms(dx, dy, dz);
}

// Eight candidates per round: their squared distances (above), the tests as one mask, the accepted
// indices and distances packed to the front by compress and stored whole (the slack takes the
// rest). Only the last round masks its loads (masked loads are slow on AMD's AVX-512 CPUs:
// core/avx512_partner_loads.hpp).
template <int D>
__attribute__((target("avx512f,avx512vl"))) std::size_t scan_avx512(const std::uint32_t* js, const Vec<D>* xs,
                                                                     std::uint32_t s0, std::uint32_t s1,
                                                                     const ScanTarget<D>& t, std::uint32_t* out,
                                                                     double* d2) {
  const __m512d r2 = _mm512_set1_pd(t.r2);
  const __m256i self = _mm256_set1_epi32(static_cast<int>(t.self));
  const __m256i limit = _mm256_set1_epi32(static_cast<int>(t.limit));
  static_assert(sizeof(Vec<D>) == D * sizeof(double), "positions are read as interleaved components");
  const double* base = reinterpret_cast<const double*>(xs);
  std::size_t found = 0;
  for (std::uint32_t s = s0; s < s1; s += 8) {
    const unsigned n = s1 - s < 8 ? s1 - s : 8;
    const auto live = static_cast<__mmask8>((1u << n) - 1u);
    // Entries loaded: whole vectors where the slots go on past the range (the lanes beyond it are
    // not live), else only the range's (masked loads).
    const unsigned m = std::size_t{s} + 8 <= t.readable ? 8 : n;
    const __m512d dist2 = squared_distances(base + D * std::size_t{s}, m, t.x);
    const __m256i j = avx512::load_u32(js + s, m);
    __mmask8 keep = _mm512_mask_cmp_pd_mask(live, dist2, r2, _CMP_LT_OQ);
    keep = _mm256_mask_cmpneq_epu32_mask(keep, j, self);
    keep = _mm256_mask_cmplt_epu32_mask(keep, j, limit);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + found), _mm256_maskz_compress_epi32(keep, j));
    if (d2) _mm512_storeu_pd(d2 + found, _mm512_maskz_compress_pd(keep, dist2));
    found += static_cast<std::size_t>(__builtin_popcount(keep));
  }
  return found;
}

// In place: a round stores at or before the entries it has loaded.
__attribute__((target("avx512f,avx512vl"))) std::size_t keep_avx512(std::uint32_t* idx, const double* d2,
                                                                     std::size_t n, double r2) {
  const __m512d radius2 = _mm512_set1_pd(r2);
  std::size_t kept = 0;
  for (std::size_t k = 0; k < n; k += 8) {
    const auto live = static_cast<__mmask8>(n - k < 8 ? (1u << (n - k)) - 1u : 0xFFu);
    const __m256i j = avx512::load_u32(idx + k, n - k);
    const __mmask8 keep = _mm512_mask_cmp_pd_mask(live, avx512::load_f64(d2 + k, n - k), radius2, _CMP_LT_OQ);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(idx + kept), _mm256_maskz_compress_epi32(keep, j));
    kept += static_cast<std::size_t>(__builtin_popcount(keep));
  }
  return kept;
}

// Eight entries per round: the partners' h loaded by index (no gathers), the test as a mask, the
// kept indices and distances packed to the front (in place: a round stores at or before what it
// has loaded). 2 h and its square as in the scalar test, so the same entries are kept. Whole rounds
// only, so that no store reaches past entry n (the entries after n are the caller's: pair_scan.hpp
// keeps its later candidates there); the last, partial round is the scalar loop's.
__attribute__((target("avx512f,avx512vl"))) std::size_t beyond_avx512(std::uint32_t* idx, double* d2, std::size_t n,
                                                                       const double* h) {
  const __m512d two = _mm512_set1_pd(2.0);
  std::size_t kept = 0, k = 0;
  for (; n - k >= 8; k += 8) {
    const __m256i j = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(idx + k));
    const __m512d s = _mm512_mul_pd(two, avx512::load_singles(h, avx512::round8(idx + k, 8)));
    const __m512d r2 = _mm512_loadu_pd(d2 + k);
    const __mmask8 keep = _mm512_cmp_pd_mask(r2, _mm512_mul_pd(s, s), _CMP_GE_OQ);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(idx + kept), _mm256_maskz_compress_epi32(keep, j));
    _mm512_storeu_pd(d2 + kept, _mm512_maskz_compress_pd(keep, r2));
    kept += static_cast<std::size_t>(__builtin_popcount(keep));
  }
  return kept + keep_beyond_supports_scalar(idx + k, d2 + k, n - k, h, idx + kept, d2 + kept);
}

// The meeting point by counting the earlier entries eight at a time (their slots loaded by index:
// no chain of dependent loads as in a bisection; the list is sorted, so the count stops at the
// first vector that is not all earlier), then the earlier entries' positions and h loaded and
// tested (loads by index, not gathers: core/avx512_partner_loads.hpp).
__attribute__((target("avx512f,avx512vl"))) EarlierPartners earlier_avx512(const std::uint32_t* js, std::size_t n,
                                                                            std::uint32_t slot_i,
                                                                            const std::uint32_t* slot, const Vec<2>& xi,
                                                                            const Vec<2>* pos, const double* h,
                                                                            std::uint32_t limit,
                                                                            std::uint32_t* lacking) {
  EarlierPartners r{0, 0};
  const __m256i own = _mm256_set1_epi32(static_cast<int>(slot_i));
  for (std::size_t k = 0; k < n; k += 8) {
    const std::size_t count = std::min<std::size_t>(8, n - k);
    const auto live = static_cast<__mmask8>((1u << count) - 1u);
    const __m256i s = avx512::load_u32_singles(slot, avx512::round8(js + k, count));
    const __mmask8 earlier = _mm256_mask_cmplt_epu32_mask(live, s, own);
    r.count += static_cast<std::size_t>(__builtin_popcount(earlier));
    if (earlier != live) break;
  }
  const __m512d x = _mm512_set1_pd(xi[0]), y = _mm512_set1_pd(xi[1]), four = _mm512_set1_pd(4.0);
  const __m256i bound = _mm256_set1_epi32(static_cast<int>(limit));
  const double* base = reinterpret_cast<const double*>(pos);
  for (std::size_t k = 0; k < r.count; k += 8) {
    const std::size_t count = std::min<std::size_t>(8, r.count - k);
    const auto live = static_cast<__mmask8>((1u << count) - 1u);
    const __m256i j = avx512::load_u32(js + k, count);
    const __mmask8 wanted = _mm256_mask_cmplt_epu32_mask(live, j, bound);
    const avx512::Round8 partners = avx512::round8(js + k, count);
    __m512d xj, yj;
    avx512::load_pairs(base, partners, xj, yj);
    const __m512d hj = avx512::load_singles(h, partners);
    const __m512d dx = _mm512_sub_pd(x, xj), dy = _mm512_sub_pd(y, yj);
#ifdef __FMA__
    const __m512d dist2 = _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dx, dx));  // as norm2 with FMA
#else
    const __m512d dist2 = _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy));
#endif
    const __mmask8 lack = _mm512_mask_cmp_pd_mask(wanted, dist2, _mm512_mul_pd(_mm512_mul_pd(four, hj), hj), _CMP_GE_OQ);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(lacking + r.lacking), _mm256_maskz_compress_epi32(lack, j));
    r.lacking += static_cast<std::size_t>(__builtin_popcount(lack));
  }
  return r;
}

// AVX2 has no compress: the accepted lanes of a round of four are moved to the front by a shuffle
// from a table indexed by the 4-bit acceptance mask (for 32-bit indices a byte shuffle, for doubles
// a permute of 32-bit halves).
struct CompressTables {
  alignas(16) std::uint8_t bytes[16][16];  // _mm_shuffle_epi8 control for four 32-bit lanes
  alignas(32) std::uint32_t halves[16][8];  // _mm256_permutevar8x32_epi32 control for four doubles
};

constexpr CompressTables make_compress_tables() {
  CompressTables t{};
  for (unsigned m = 0; m < 16; ++m) {
    unsigned o = 0;
    for (unsigned l = 0; l < 4; ++l) {
      if (!(m >> l & 1u)) continue;
      for (unsigned b = 0; b < 4; ++b) t.bytes[m][4 * o + b] = static_cast<std::uint8_t>(4 * l + b);
      t.halves[m][2 * o] = 2 * l;
      t.halves[m][2 * o + 1] = 2 * l + 1;
      ++o;
    }
    for (; o < 4; ++o) {  // the rest: anything (the slack takes it); the first lane
      for (unsigned b = 0; b < 4; ++b) t.bytes[m][4 * o + b] = static_cast<std::uint8_t>(b);
      t.halves[m][2 * o] = 0;
      t.halves[m][2 * o + 1] = 1;
    }
  }
  return t;
}

constexpr CompressTables kCompress = make_compress_tables();

// Four candidates per round: positions (x, y interleaved) loaded as two vectors and split by an
// unpack and a lane permute, the tests as a 4-bit mask, the accepted indices and distances moved
// to the front and stored whole (the slack takes the rest). The last, partial round is the scalar
// loop's (the same operations on each candidate).
[[gnu::target("avx2")]] std::size_t scan_avx2(const std::uint32_t* js, const Vec<2>* xs, std::uint32_t s0,
                                              std::uint32_t s1, const ScanTarget<2>& t, std::uint32_t* out,
                                              double* d2) {
  const __m256d x = _mm256_set1_pd(t.x[0]), y = _mm256_set1_pd(t.x[1]), r2 = _mm256_set1_pd(t.r2);
  // Unsigned j < limit as a signed comparison of both with the sign bit flipped.
  const __m128i sign = _mm_set1_epi32(INT32_MIN);
  const __m128i self = _mm_set1_epi32(static_cast<int>(t.self));
  const __m128i limit = _mm_xor_si128(_mm_set1_epi32(static_cast<int>(t.limit)), sign);
  const double* base = reinterpret_cast<const double*>(xs);
  std::size_t found = 0;
  std::uint32_t s = s0;
  for (; s1 - s >= 4; s += 4) {
    const __m256d a = _mm256_loadu_pd(base + 2 * std::size_t{s});      // x0 y0 x1 y1
    const __m256d b = _mm256_loadu_pd(base + 2 * std::size_t{s} + 4);  // x2 y2 x3 y3
    const __m256d dx = _mm256_sub_pd(_mm256_permute4x64_pd(_mm256_unpacklo_pd(a, b), 0xD8), x);
    const __m256d dy = _mm256_sub_pd(_mm256_permute4x64_pd(_mm256_unpackhi_pd(a, b), 0xD8), y);
#ifdef __FMA__
    const __m256d dist2 = _mm256_fmadd_pd(dy, dy, _mm256_mul_pd(dx, dx));  // as norm2 with FMA
#else
    const __m256d dist2 = _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy));
#endif
    const __m128i j = _mm_loadu_si128(reinterpret_cast<const __m128i*>(js + s));
    const __m128i ok = _mm_andnot_si128(_mm_cmpeq_epi32(j, self), _mm_cmplt_epi32(_mm_xor_si128(j, sign), limit));
    const int keep = _mm256_movemask_pd(_mm256_cmp_pd(dist2, r2, _CMP_LT_OQ)) & _mm_movemask_ps(_mm_castsi128_ps(ok));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + found),
                     _mm_shuffle_epi8(j, _mm_load_si128(reinterpret_cast<const __m128i*>(kCompress.bytes[keep]))));
    if (d2) {
      const __m256i to_front = _mm256_load_si256(reinterpret_cast<const __m256i*>(kCompress.halves[keep]));
      _mm256_storeu_pd(d2 + found, _mm256_castsi256_pd(_mm256_permutevar8x32_epi32(_mm256_castpd_si256(dist2), to_front)));
    }
    found += static_cast<std::size_t>(__builtin_popcount(static_cast<unsigned>(keep)));
  }
  return found + scan_candidates_scalar<2>(js, xs, s, s1, t, out + found, d2 ? d2 + found : nullptr);
}

// In place: a round stores at or before the entries it has loaded.
[[gnu::target("avx2")]] std::size_t keep_avx2(std::uint32_t* idx, const double* d2, std::size_t n, double r2) {
  const __m256d radius2 = _mm256_set1_pd(r2);
  std::size_t kept = 0, k = 0;
  for (; n - k >= 4; k += 4) {
    const __m128i j = _mm_loadu_si128(reinterpret_cast<const __m128i*>(idx + k));
    const int keep = _mm256_movemask_pd(_mm256_cmp_pd(_mm256_loadu_pd(d2 + k), radius2, _CMP_LT_OQ));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(idx + kept),
                     _mm_shuffle_epi8(j, _mm_load_si128(reinterpret_cast<const __m128i*>(kCompress.bytes[keep]))));
    kept += static_cast<std::size_t>(__builtin_popcount(static_cast<unsigned>(keep)));
  }
  return keep_from(idx, d2, k, n, kept, r2);  // the scalar loop's remainder
}

#endif

}  // namespace

std::size_t scan_candidates(const std::uint32_t* js, const Vec<2>* xs, std::uint32_t s0, std::uint32_t s1,
                            const ScanTarget<2>& target, std::uint32_t* out, double* d2) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  switch (vector_isa()) {
    case VectorIsa::avx512: return scan_avx512(js, xs, s0, s1, target, out, d2);
    case VectorIsa::avx2: return scan_avx2(js, xs, s0, s1, target, out, d2);
    case VectorIsa::baseline: break;
  }
#endif
  return scan_candidates_scalar<2>(js, xs, s0, s1, target, out, d2);
}

std::size_t scan_candidates(const std::uint32_t* js, const Vec<3>* xs, std::uint32_t s0, std::uint32_t s1,
                            const ScanTarget<3>& target, std::uint32_t* out, double* d2) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  if (vector_isa() == VectorIsa::avx512) return scan_avx512(js, xs, s0, s1, target, out, d2);
#endif
  return scan_candidates_scalar<3>(js, xs, s0, s1, target, out, d2);
}

EarlierPartners earlier_partners(const std::uint32_t* js, std::size_t n, std::uint32_t slot_i, const std::uint32_t* slot,
                                 const Vec<2>& xi, const Vec<2>* pos, const double* h, std::uint32_t limit,
                                 std::uint32_t* lacking) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  if (vector_isa() == VectorIsa::avx512) return earlier_avx512(js, n, slot_i, slot, xi, pos, h, limit, lacking);
#endif
  return earlier_partners_scalar<2>(js, n, slot_i, slot, xi, pos, h, limit, lacking);
}

std::size_t keep_beyond_supports(std::uint32_t* idx, double* d2, std::size_t n, const double* h) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  if (vector_isa() == VectorIsa::avx512) return beyond_avx512(idx, d2, n, h);
#endif
  return keep_beyond_supports_scalar(idx, d2, n, h, idx, d2);
}

std::size_t keep_within(std::uint32_t* idx, const double* d2, std::size_t n, double r2) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  switch (vector_isa()) {
    case VectorIsa::avx512: return keep_avx512(idx, d2, n, r2);
    case VectorIsa::avx2: return keep_avx2(idx, d2, n, r2);
    case VectorIsa::baseline: break;
  }
#endif
  return keep_from(idx, d2, 0, n, 0, r2);
}

}  // namespace sphdisk
