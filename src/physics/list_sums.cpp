#include "physics/list_sums.hpp"

#include <algorithm>
#include <cstddef>

#include "core/avx512_partner_loads.hpp"
#include "core/vector_isa.hpp"

// Compiled with -ffp-contract=off (src/CMakeLists.txt): a product added to a sum must not be fused
// in one path and not the other (both paths are in this file, so native builds agree too).
#ifdef SPHDISK_X86_VECTOR_DISPATCH
#include <immintrin.h>
#endif

namespace sphdisk {

namespace {

#ifdef SPHDISK_X86_VECTOR_DISPATCH
// Intrinsics in their maskz forms with all lanes set where GCC 12 warns that the plain forms'
// undefined source may be used.

static_assert(sizeof(Vec<2>) == 2 * sizeof(double), "positions and velocities are read as interleaved x, y");
static_assert(offsetof(GradientSums<2>, M) == 4 * sizeof(double), "a particle's eq. 8 and moment sums are its first eight doubles");

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

// Eight partners per round: their positions, velocities and volumes loaded, the eight products of
// gradient_pair_products (pair_terms.hpp; the moment ones negated: w (-P) = -(w P) exactly) formed
// for all of them and transposed to one vector per pair, which is then weighted and added to i's sum
// and to the partner's, pair by pair in list order: the scalar loop's operations, in its order.
[[gnu::target("avx512f,avx512vl")]] void gradient_list_avx512(const GradientListData<2>& d, std::uint32_t i,
                                                                       const std::uint32_t* js, const float* F,
                                                                       std::size_t n, GradientSums<2>& sum_i) {
  const double* pos = reinterpret_cast<const double*>(d.pos);
  const double* vel = reinterpret_cast<const double*>(d.vel);
  const __m512d xi = _mm512_set1_pd(d.pos[i][0]), yi = _mm512_set1_pd(d.pos[i][1]);
  const __m512d vxi = _mm512_set1_pd(d.vel[i][0]), vyi = _mm512_set1_pd(d.vel[i][1]);
  const __m512d Vi = _mm512_set1_pd(d.volume[i]);
  __m512d sum = _mm512_loadu_pd(reinterpret_cast<const double*>(&sum_i));
  alignas(64) double wi[8], wj[8];
  for (std::size_t q = 0; q < n; q += 8) {
    const Round r = load_round(js, F, q, n);
    __m512d vxj, vyj, xj, yj;
    avx512::load_pairs(vel, r.j, vxj, vyj);
    avx512::load_pairs(pos, r.j, xj, yj);
    const __m512d dvx = _mm512_sub_pd(vxj, vxi), dvy = _mm512_sub_pd(vyj, vyi);
    const __m512d dx = _mm512_sub_pd(xi, xj), dy = _mm512_sub_pd(yi, yj);
    __m512d P[8] = {_mm512_mul_pd(dvx, dx), _mm512_mul_pd(dvx, dy), _mm512_mul_pd(dvy, dx), _mm512_mul_pd(dvy, dy),
                    negated(_mm512_mul_pd(dx, dx)), negated(_mm512_mul_pd(dx, dy)), negated(_mm512_mul_pd(dy, dx)),
                    negated(_mm512_mul_pd(dy, dy))};
    transpose8(P);
    _mm512_store_pd(wi, _mm512_mul_pd(r.f, avx512::load_singles(d.volume, r.j)));
    _mm512_store_pd(wj, _mm512_mul_pd(r.f, Vi));
    const std::size_t count = std::min<std::size_t>(8, n - q);
    for (std::size_t k = 0; k < count; ++k) {
      sum = _mm512_add_pd(sum, _mm512_mul_pd(P[k], _mm512_set1_pd(wi[k])));
      const std::uint32_t j = js[q + k];
      if (j < d.writable) {
        double* s = reinterpret_cast<double*>(d.sums + j);
        _mm512_storeu_pd(s, _mm512_add_pd(_mm512_loadu_pd(s), _mm512_mul_pd(P[k], _mm512_set1_pd(wj[k]))));
      }
    }
  }
  _mm512_storeu_pd(reinterpret_cast<double*>(&sum_i), sum);
}

#ifndef SPHDISK_SINGLE_PRECISION_FIELDS  // (stresses stored as double)
// A round's pair accelerations ((x, y) per pair in to_i and to_j) added to i's sum and subtracted
// from the writable partners' accelerations, pair by pair in list order (SSE2, in either path).
[[gnu::always_inline]] inline void add_round(const ForceListData<2>& d, const std::uint32_t* js, std::size_t count,
                                             const double* to_i, const double* to_j, __m128d& sum) {
  for (std::size_t k = 0; k < count; ++k) {
    sum = _mm_add_pd(sum, _mm_load_pd(to_i + 2 * k));
    const std::uint32_t j = js[k];
    if (j < d.writable) {
      double* a = d.acc[j].c.data();
      _mm_storeu_pd(a, _mm_sub_pd(_mm_loadu_pd(a), _mm_load_pd(to_j + 2 * k)));
    }
  }
}

// Eq. 6 without pressure or force correction, eight partners per round: positions, stresses, 1/rho
// and masses loaded, the pair forces formed for all eight, then interleaved to (x, y) per pair and
// added to i's sum and subtracted from the partner's acceleration pair by pair in list order.
[[gnu::target("avx512f,avx512vl")]] void force_list_avx512(const ForceListData<2>& d, std::uint32_t i,
                                                                    const std::uint32_t* js, const float* F,
                                                                    std::size_t n, Vec<2>& ai) {
  static_assert(sizeof(Mat<2, ReducedReal>) == 4 * sizeof(double), "stresses are read as four doubles");
  const double* pos = reinterpret_cast<const double*>(d.pos);
  const double* stress = reinterpret_cast<const double*>(d.stress);
  const __m512d xi = _mm512_set1_pd(d.pos[i][0]), yi = _mm512_set1_pd(d.pos[i][1]);
  __m512d Si[4];
  for (int c = 0; c < 4; ++c) Si[c] = _mm512_set1_pd(d.stress[i].c[static_cast<std::size_t>(c)]);
  const __m512d inv_rho_i = _mm512_set1_pd(d.inv_rho[i]), mi = _mm512_set1_pd(d.mass[i]);
  const __m512i first = _mm512_setr_epi64(0, 8, 1, 9, 2, 10, 3, 11), second = _mm512_setr_epi64(4, 12, 5, 13, 6, 14, 7, 15);
  __m128d sum = _mm_loadu_pd(ai.c.data());
  alignas(64) double to_i[16], to_j[16];
  for (std::size_t q = 0; q < n; q += 8) {
    const Round r = load_round(js, F, q, n);
    __m512d xj, yj, Sj[4];
    avx512::load_pairs(pos, r.j, xj, yj);
    avx512::load_quads(stress, r.j, Sj);
    const __m512d gx = _mm512_mul_pd(_mm512_sub_pd(xi, xj), r.f);
    const __m512d gy = _mm512_mul_pd(_mm512_sub_pd(yi, yj), r.f);
    const __m512d inv_rho_j = avx512::load_singles(d.inv_rho, r.j);
    __m512d X[4];
    for (int c = 0; c < 4; ++c) X[c] = _mm512_add_pd(_mm512_mul_pd(Si[c], inv_rho_j), _mm512_mul_pd(Sj[c], inv_rho_i));
    const __m512d fx = _mm512_add_pd(_mm512_mul_pd(X[0], gx), _mm512_mul_pd(X[1], gy));  // contract(X, g)
    const __m512d fy = _mm512_add_pd(_mm512_mul_pd(X[2], gx), _mm512_mul_pd(X[3], gy));
    const __m512d mj = avx512::load_singles(d.mass, r.j);
    const __m512d ax = _mm512_mul_pd(fx, mj), ay = _mm512_mul_pd(fy, mj);
    const __m512d bx = _mm512_mul_pd(fx, mi), by = _mm512_mul_pd(fy, mi);
    _mm512_store_pd(to_i, _mm512_permutex2var_pd(ax, first, ay));
    _mm512_store_pd(to_i + 8, _mm512_permutex2var_pd(ax, second, ay));
    _mm512_store_pd(to_j, _mm512_permutex2var_pd(bx, first, by));
    _mm512_store_pd(to_j + 8, _mm512_permutex2var_pd(bx, second, by));
    add_round(d, js + q, std::min<std::size_t>(8, n - q), to_i, to_j, sum);
  }
  _mm_storeu_pd(ai.c.data(), sum);
}
#endif

// The scalar gradient loop compiled for AVX2: a pair's eight sums in two instructions, not four.
// (The force loop compiled so was slower; with AVX2 only it runs the scalar loop: docs/design.md,
// "Modes kept and retired".)
[[gnu::target("avx2")]] void gradient_list_avx2(const GradientListData<2>& d, std::uint32_t i, std::span<const std::uint32_t> js,
                                                std::span<const float> F, GradientSums<2>& sum_i) {
  add_gradient_list_scalar(d, i, js, F, sum_i);
}


#endif

}  // namespace

void add_gradient_list(const GradientListData<2>& d, std::uint32_t i, std::span<const std::uint32_t> js,
                       std::span<const float> F, GradientSums<2>& sum_i) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  if (d.scales) return add_gradient_list_scalar(d, i, js, F, sum_i);
  if (vector_isa() == VectorIsa::avx512) return gradient_list_avx512(d, i, js.data(), F.data(), js.size(), sum_i);
  if (vector_isa() == VectorIsa::avx2) return gradient_list_avx2(d, i, js, F, sum_i);
#endif
  add_gradient_list_scalar(d, i, js, F, sum_i);
}

void add_force_list(const ForceListData<2>& d, std::uint32_t i, std::span<const std::uint32_t> js, std::span<const float> F,
                    Vec<2>& ai, double& du_i) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
#ifndef SPHDISK_SINGLE_PRECISION_FIELDS
  if (!d.with_pressure && !d.force_correction && !d.consistent) {
    if (vector_isa() == VectorIsa::avx512) return force_list_avx512(d, i, js.data(), F.data(), js.size(), ai);
  }
#endif
#endif
  add_force_list_scalar(d, i, js, F, ai, du_i);
}

}  // namespace sphdisk
