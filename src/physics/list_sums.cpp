#include "physics/list_sums.hpp"

#include <algorithm>
#include <cstddef>

#include "core/avx512_norms.hpp"
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

// 3D, one pair at a time over its components: u = (dx, 0, dv, 0) is permuted into the two sides of
// the 18 products of gradient_pair_products (V_ab = dv_a dx_b at 3a + b, then M_ab = dx_a dx_b at
// 9 + 3a + b, the moment ones negated: w (-P) = -(w P) exactly) in two vectors of eight and one of
// two, which are weighted and added to i's sum and to the partner's, pair by pair in list order:
// the scalar loop's operations, in its order.
[[gnu::target("avx512f,avx512vl")]] void gradient_list_avx512(const GradientListData<3>& d, std::uint32_t i,
                                                              const std::uint32_t* js, const float* F, std::size_t n,
                                                              GradientSums<3>& sum_i) {
  const double* pos = reinterpret_cast<const double*>(d.pos);
  const double* vel = reinterpret_cast<const double*>(d.vel);
  const __m256d xi = load_xyz(pos + 3 * std::size_t{i}), vi = load_xyz(vel + 3 * std::size_t{i});
  // Lanes of u: dx0 dx1 dx2 0 dv0 dv1 dv2 0.
  const __m512i left0 = _mm512_setr_epi64(4, 4, 4, 5, 5, 5, 6, 6), right0 = _mm512_setr_epi64(0, 1, 2, 0, 1, 2, 0, 1);
  const __m512i left1 = _mm512_setr_epi64(6, 0, 0, 0, 1, 1, 1, 2), right1 = _mm512_setr_epi64(2, 0, 1, 2, 0, 1, 2, 0);
  const __m512i left2 = _mm512_setr_epi64(2, 2, 0, 0, 0, 0, 0, 0), right2 = _mm512_setr_epi64(1, 2, 0, 0, 0, 0, 0, 0);
  const __m512i sign1 = _mm512_setr_epi64(0, INT64_MIN, INT64_MIN, INT64_MIN, INT64_MIN, INT64_MIN, INT64_MIN, INT64_MIN);
  double* own = reinterpret_cast<double*>(&sum_i);
  __m512d s0 = _mm512_loadu_pd(own), s1 = _mm512_loadu_pd(own + 8);
  __m128d s2 = _mm_loadu_pd(own + 16);
  for (std::size_t q = 0; q < n; ++q) {
    const std::uint32_t j = js[q];
    const __m256d dx = _mm256_sub_pd(xi, load_xyz(pos + 3 * std::size_t{j}));
    const __m256d dv = _mm256_sub_pd(load_xyz(vel + 3 * std::size_t{j}), vi);
    const __m512d u = avx512::joined(dx, dv);
    const __m512d p0 = _mm512_mul_pd(_mm512_maskz_permutexvar_pd(0xFF, left0, u), _mm512_maskz_permutexvar_pd(0xFF, right0, u));
    const __m512d p1 = _mm512_castsi512_pd(_mm512_xor_si512(
        _mm512_castpd_si512(_mm512_mul_pd(_mm512_maskz_permutexvar_pd(0xFF, left1, u), _mm512_maskz_permutexvar_pd(0xFF, right1, u))), sign1));
    const __m512d p2 = negated(_mm512_mul_pd(_mm512_maskz_permutexvar_pd(0xFF, left2, u), _mm512_maskz_permutexvar_pd(0xFF, right2, u)));
    const double f = static_cast<double>(F[q]);
    const __m512d wi = _mm512_set1_pd(f * d.volume[j]);
    s0 = _mm512_add_pd(s0, _mm512_mul_pd(p0, wi));
    s1 = _mm512_add_pd(s1, _mm512_mul_pd(p1, wi));
    s2 = _mm_add_pd(s2, low_pair(_mm512_mul_pd(p2, wi)));
    if (j < d.writable) {
      const __m512d wj = _mm512_set1_pd(f * d.volume[i]);
      double* s = reinterpret_cast<double*>(d.sums + j);
      _mm512_storeu_pd(s, _mm512_add_pd(_mm512_loadu_pd(s), _mm512_mul_pd(p0, wj)));
      _mm512_storeu_pd(s + 8, _mm512_add_pd(_mm512_loadu_pd(s + 8), _mm512_mul_pd(p1, wj)));
      _mm_storeu_pd(s + 16, _mm_add_pd(_mm_loadu_pd(s + 16), low_pair(_mm512_mul_pd(p2, wj))));
    }
  }
  _mm512_storeu_pd(own, s0);
  _mm512_storeu_pd(own + 8, s1);
  _mm_storeu_pd(own + 16, s2);
}

#ifndef SPHDISK_SINGLE_PRECISION_FIELDS  // (stresses stored as double)
// A round's pair accelerations ((x, y) per pair in to_i and to_j) added to i's sum and subtracted
// from (Subtract; else added to) the writable partners' accelerations, pair by pair in list order
// (SSE2, in either path).
template <bool Subtract>
[[gnu::always_inline]] inline void add_round(const ForceListData<2>& d, const std::uint32_t* js, std::size_t count,
                                             const double* to_i, const double* to_j, __m128d& sum) {
  for (std::size_t k = 0; k < count; ++k) {
    sum = _mm_add_pd(sum, _mm_load_pd(to_i + 2 * k));
    const std::uint32_t j = js[k];
    if (j < d.writable) {
      double* a = d.acc[j].c.data();
      const __m128d t = _mm_load_pd(to_j + 2 * k);
      _mm_storeu_pd(a, Subtract ? _mm_sub_pd(_mm_loadu_pd(a), t) : _mm_add_pd(_mm_loadu_pd(a), t));
    }
  }
}

// x and y of eight pairs interleaved to (x, y) per pair in out[16].
[[gnu::target("avx512f"), gnu::always_inline]] inline void interleave(__m512d x, __m512d y, double* out) {
  const __m512i first = _mm512_setr_epi64(0, 8, 1, 9, 2, 10, 3, 11), second = _mm512_setr_epi64(4, 12, 5, 13, 6, 14, 7, 15);
  _mm512_store_pd(out, _mm512_permutex2var_pd(x, first, y));
  _mm512_store_pd(out + 8, _mm512_permutex2var_pd(x, second, y));
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
    interleave(ax, ay, to_i);
    interleave(bx, by, to_j);
    add_round<true>(d, js + q, std::min<std::size_t>(8, n - q), to_i, to_j, sum);
  }
  _mm_storeu_pd(ai.c.data(), sum);
}

// The consistent divergence of eq. 6 (consistent_viscous_pair with linear_corrected_gradients and
// the ln rho_j - ln rho_i that log_rho holds), with the pressure force and its work where Pressure
// (no artificial viscosity; force_list_terms<2, Pressure, false, true>, list_sums.hpp), eight
// partners per round: both particles' terms formed for all eight with the scalar loop's operations
// in its order, then added pair by pair in list order as the scalar loop adds them (the viscous
// term, then the pressure's work and force).
template <bool Pressure>
[[gnu::target("avx512f,avx512vl")]] void consistent_force_list_avx512(const ForceListData<2>& d, std::uint32_t i,
                                                                      const std::uint32_t* js, const float* F, std::size_t n,
                                                                      Vec<2>& ai, double& du_i) {
  const double* pos = reinterpret_cast<const double*>(d.pos);
  const double* stress = reinterpret_cast<const double*>(d.stress);
  const double* correction = reinterpret_cast<const double*>(d.correction);
  const __m512d xi = _mm512_set1_pd(d.pos[i][0]), yi = _mm512_set1_pd(d.pos[i][1]);
  __m512d Si[4], Ci[4];
  for (std::size_t c = 0; c < 4; ++c) Si[c] = _mm512_set1_pd(d.stress[i].c[c]), Ci[c] = _mm512_set1_pd(d.correction[i].c[c]);
  const __m512d log_rho_i = _mm512_set1_pd(d.log_rho[i]);
  const __m512d Vi = _mm512_set1_pd(d.volume[i]);
  const __m512d vxi = _mm512_set1_pd(d.vel[i][0]), vyi = _mm512_set1_pd(d.vel[i][1]);
  const __m512d mi = _mm512_set1_pd(d.mass[i]), Pr_i = _mm512_set1_pd(Pressure ? d.p_over_rho2[i] : 0.0);
  const double* vel = reinterpret_cast<const double*>(d.vel);
  __m128d sum = _mm_loadu_pd(ai.c.data());
  alignas(64) double to_i[16], to_j[16], press_i[16], press_j[16], work_i[8], work_j[8];
  for (std::size_t q = 0; q < n; q += 8) {
    const Round r = load_round(js, F, q, n);
    __m512d xj, yj, Sj[4], Cj[4];
    avx512::load_pairs(pos, r.j, xj, yj);
    avx512::load_quads(stress, r.j, Sj);
    avx512::load_quads(correction, r.j, Cj);
    const __m512d gx = _mm512_mul_pd(_mm512_sub_pd(xi, xj), r.f);
    const __m512d gy = _mm512_mul_pd(_mm512_sub_pd(yi, yj), r.f);
    const __m512d dl = _mm512_sub_pd(avx512::load_singles(d.log_rho, r.j), log_rho_i);
    const __m512d Vj = avx512::load_singles(d.volume, r.j);
    // G_i = C_i g, G_j = C_j g (contract: the first product, then the second added)
    const __m512d Gix = _mm512_add_pd(_mm512_mul_pd(Ci[0], gx), _mm512_mul_pd(Ci[1], gy));
    const __m512d Giy = _mm512_add_pd(_mm512_mul_pd(Ci[2], gx), _mm512_mul_pd(Ci[3], gy));
    const __m512d Gjx = _mm512_add_pd(_mm512_mul_pd(Cj[0], gx), _mm512_mul_pd(Cj[1], gy));
    const __m512d Gjy = _mm512_add_pd(_mm512_mul_pd(Cj[2], gx), _mm512_mul_pd(Cj[3], gy));
    __m512d Xi[4], Xj[4];
    for (std::size_t c = 0; c < 4; ++c) {
      const __m512d dS = _mm512_sub_pd(Sj[c], Si[c]);
      Xi[c] = _mm512_add_pd(dS, _mm512_mul_pd(Si[c], dl));
      Xj[c] = _mm512_add_pd(dS, _mm512_mul_pd(Sj[c], dl));
    }
    const __m512d ax = _mm512_mul_pd(_mm512_add_pd(_mm512_mul_pd(Xi[0], Gix), _mm512_mul_pd(Xi[1], Giy)), Vj);
    const __m512d ay = _mm512_mul_pd(_mm512_add_pd(_mm512_mul_pd(Xi[2], Gix), _mm512_mul_pd(Xi[3], Giy)), Vj);
    const __m512d bx = _mm512_mul_pd(_mm512_add_pd(_mm512_mul_pd(Xj[0], Gjx), _mm512_mul_pd(Xj[1], Gjy)), Vi);
    const __m512d by = _mm512_mul_pd(_mm512_add_pd(_mm512_mul_pd(Xj[2], Gjx), _mm512_mul_pd(Xj[3], Gjy)), Vi);
    interleave(ax, ay, to_i);
    interleave(bx, by, to_j);
    const std::size_t count = std::min<std::size_t>(8, n - q);
    if constexpr (!Pressure) {
      add_round<false>(d, js + q, count, to_i, to_j, sum);
    } else {
      // pressure_pair, subtracted from a zero f, and pressure_work_pair with v_ij . g
      const __m512d mj = avx512::load_singles(d.mass, r.j), Pr_j = avx512::load_singles(d.p_over_rho2, r.j);
      const __m512d Pr = _mm512_add_pd(Pr_i, Pr_j);
      const __m512d fx = _mm512_sub_pd(_mm512_setzero_pd(), _mm512_mul_pd(gx, Pr));
      const __m512d fy = _mm512_sub_pd(_mm512_setzero_pd(), _mm512_mul_pd(gy, Pr));
      interleave(_mm512_mul_pd(fx, mj), _mm512_mul_pd(fy, mj), press_i);
      interleave(_mm512_mul_pd(fx, mi), _mm512_mul_pd(fy, mi), press_j);
      __m512d vxj, vyj;
      avx512::load_pairs(vel, r.j, vxj, vyj);
      const __m512d work = _mm512_add_pd(_mm512_mul_pd(_mm512_sub_pd(vxi, vxj), gx), _mm512_mul_pd(_mm512_sub_pd(vyi, vyj), gy));
      _mm512_store_pd(work_i, _mm512_mul_pd(_mm512_mul_pd(Pr_i, mj), work));
      _mm512_store_pd(work_j, _mm512_mul_pd(_mm512_mul_pd(Pr_j, mi), work));
      for (std::size_t k = 0; k < count; ++k) {
        const std::uint32_t j = js[q + k];
        const bool writable = j < d.writable;
        double* a = writable ? d.acc[j].c.data() : nullptr;
        sum = _mm_add_pd(sum, _mm_load_pd(to_i + 2 * k));
        if (writable) _mm_storeu_pd(a, _mm_add_pd(_mm_loadu_pd(a), _mm_load_pd(to_j + 2 * k)));
        du_i += work_i[k];
        if (writable && d.du_dt) d.du_dt[j] += work_j[k];
        sum = _mm_add_pd(sum, _mm_load_pd(press_i + 2 * k));
        if (writable) _mm_storeu_pd(a, _mm_sub_pd(_mm_loadu_pd(a), _mm_load_pd(press_j + 2 * k)));
      }
    }
  }
  _mm_storeu_pd(ai.c.data(), sum);
}

// Records of three doubles at base + 3 j (x, y, z): component c of the eight partners in c3[c].
[[gnu::target("avx512f,avx512vl"), gnu::always_inline]] inline void load_triples(const double* base,
                                                                                 const avx512::Round8& r, __m512d c3[3]) {
  __m512d a[4];  // partners 2k and 2k + 1: x y z 0 x y z 0
  for (std::size_t k = 0; k < 4; ++k) a[k] = avx512::joined(load_xyz(base + 3 * r.j[2 * k]), load_xyz(base + 3 * r.j[2 * k + 1]));
  const __m512i xy = _mm512_setr_epi64(0, 4, 8, 12, 1, 5, 9, 13), zz = _mm512_setr_epi64(2, 6, 10, 14, 2, 6, 10, 14);
  const __m512i low = _mm512_setr_epi64(0, 1, 2, 3, 8, 9, 10, 11), high = _mm512_setr_epi64(4, 5, 6, 7, 12, 13, 14, 15);
  const __m512d xy01 = _mm512_permutex2var_pd(a[0], xy, a[1]), xy23 = _mm512_permutex2var_pd(a[2], xy, a[3]);
  const __m512d z01 = _mm512_permutex2var_pd(a[0], zz, a[1]), z23 = _mm512_permutex2var_pd(a[2], zz, a[3]);
  c3[0] = _mm512_permutex2var_pd(xy01, low, xy23);
  c3[1] = _mm512_permutex2var_pd(xy01, high, xy23);
  c3[2] = _mm512_permutex2var_pd(z01, low, z23);
}

// Records of nine doubles at base + 9 j (3D stresses): component c of the eight partners in c9[c].
[[gnu::target("avx512f,avx512vl"), gnu::always_inline]] inline void load_nines(const double* base, const avx512::Round8& r,
                                                                               __m512d c9[9]) {
  for (std::size_t k = 0; k < 8; ++k) c9[k] = _mm512_loadu_pd(base + 9 * r.j[k]);
  transpose8(c9);
  c9[8] = _mm512_setr_pd(base[9 * r.j[0] + 8], base[9 * r.j[1] + 8], base[9 * r.j[2] + 8], base[9 * r.j[3] + 8],
                         base[9 * r.j[4] + 8], base[9 * r.j[5] + 8], base[9 * r.j[6] + 8], base[9 * r.j[7] + 8]);
}

// 3D eq. 6 in the conservative form with pressure (no force correction), with or without the
// artificial viscosity: eight partners per round, every pair term of force_list_terms<3, true,
// false> (list_sums.hpp) formed for all of them with its operations in its order, then added to i's
// sums and to the writable partners' pair by pair in list order.
template <bool ArtificialViscosity>
[[gnu::target("avx512f,avx512vl")]] void pressure_force_list_avx512(const ForceListData<3>& d, std::uint32_t i,
                                                                    const std::uint32_t* js, const float* F, std::size_t n,
                                                                    Vec<3>& ai, double& du_i) {
  static_assert(sizeof(Mat<3, ReducedReal>) == 9 * sizeof(double), "stresses are read as nine doubles");
  const double* pos = reinterpret_cast<const double*>(d.pos);
  const double* vel = reinterpret_cast<const double*>(d.vel);
  const double* stress = reinterpret_cast<const double*>(d.stress);
  __m512d xi[3], vi[3], Si[9];
  for (int c = 0; c < 3; ++c) xi[c] = _mm512_set1_pd(d.pos[i][c]), vi[c] = _mm512_set1_pd(d.vel[i][c]);
  for (std::size_t c = 0; c < 9; ++c) Si[c] = _mm512_set1_pd(d.stress[i].c[c]);
  const __m512d inv_rho_i = _mm512_set1_pd(d.inv_rho[i]), mi = _mm512_set1_pd(d.mass[i]);
  const __m512d Pr_i = _mm512_set1_pd(d.p_over_rho2[i]);
  __m512d ci = _mm512_setzero_pd(), limiter_i = ci, alpha_i = ci, beta = ci, minus_half = ci;
  if constexpr (ArtificialViscosity) {
    ci = _mm512_set1_pd(d.sound_speed[i]);
    limiter_i = _mm512_set1_pd(d.limiter ? d.limiter[i] : 1.0);
    alpha_i = _mm512_set1_pd(d.av_alpha[i]);
    beta = _mm512_set1_pd(d.av_beta);
    minus_half = _mm512_set1_pd(-0.5);
  }
  alignas(64) double to_i[3][8], to_j[3][8], work_i[8], work_j[8], signal[8];
  double signal_i = 0.0;
  for (std::size_t q = 0; q < n; q += 8) {
    const Round r = load_round(js, F, q, n);
    __m512d xj[3], vj[3], Sj[9];
    load_triples(pos, r.j, xj);
    load_triples(vel, r.j, vj);
    load_nines(stress, r.j, Sj);
    __m512d dx[3], g[3], vij[3];
    for (std::size_t c = 0; c < 3; ++c) {
      dx[c] = _mm512_sub_pd(xi[c], xj[c]);
      g[c] = _mm512_mul_pd(dx[c], r.f);
      vij[c] = _mm512_sub_pd(vi[c], vj[c]);
    }
    const __m512d inv_rho_j = avx512::load_singles(d.inv_rho, r.j), mj = avx512::load_singles(d.mass, r.j);
    __m512d f[3];  // conservative_viscous_pair: (S_i / rho_j + S_j / rho_i) . g
    for (std::size_t a = 0; a < 3; ++a) {
      __m512d X[3];
      for (std::size_t b = 0; b < 3; ++b)
        X[b] = _mm512_add_pd(_mm512_mul_pd(Si[3 * a + b], inv_rho_j), _mm512_mul_pd(Sj[3 * a + b], inv_rho_i));
      f[a] = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(X[0], g[0]), _mm512_mul_pd(X[1], g[1])), _mm512_mul_pd(X[2], g[2]));
    }
    __m512d Pr_to_i = Pr_i, Pr_to_j = avx512::load_singles(d.p_over_rho2, r.j);
    if constexpr (ArtificialViscosity) {
      const __m512d cj = avx512::load_singles(d.sound_speed, r.j);
      const __m512d limiter_j = d.limiter ? avx512::load_singles(d.limiter, r.j) : _mm512_set1_pd(1.0);
      const __m512d alpha_j = avx512::load_singles(d.av_alpha, r.j);
      // approach_speed: dot(vij, xij) / |xij| where negative, else 0
      const __m512d approach =
          _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(vij[0], dx[0]), _mm512_mul_pd(vij[1], dx[1])), _mm512_mul_pd(vij[2], dx[2]));
      const __mmask8 approaching = _mm512_cmp_pd_mask(approach, _mm512_setzero_pd(), _CMP_LT_OQ);
      const __m512d w =
          _mm512_maskz_div_pd(approaching, approach, _mm512_maskz_sqrt_pd(0xFF, avx512::squared_norms(dx[0], dx[1], dx[2])));
      const __m512d bw = _mm512_mul_pd(beta, w);
      // artificial_viscosity_pair: -1/2 f (alpha c - beta w) w / rho, for each side
      const __m512d av_i = _mm512_mul_pd(
          _mm512_mul_pd(_mm512_mul_pd(_mm512_mul_pd(minus_half, limiter_i), _mm512_sub_pd(_mm512_mul_pd(alpha_i, ci), bw)), w),
          inv_rho_i);
      const __m512d av_j = _mm512_mul_pd(
          _mm512_mul_pd(_mm512_mul_pd(_mm512_mul_pd(minus_half, limiter_j), _mm512_sub_pd(_mm512_mul_pd(alpha_j, cj), bw)), w),
          inv_rho_j);
      Pr_to_i = _mm512_add_pd(Pr_to_i, av_i);
      Pr_to_j = _mm512_add_pd(Pr_to_j, av_j);
      // pair_signal_speed: the larger sound speed, minus beta w
      const __m512d larger = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(ci, cj, _CMP_GT_OQ), cj, ci);
      _mm512_store_pd(signal, _mm512_sub_pd(larger, bw));
    }
    const __m512d Pr = _mm512_add_pd(Pr_to_i, Pr_to_j);  // pressure_pair: g (Pr_i + Pr_j), subtracted
    for (std::size_t c = 0; c < 3; ++c) f[c] = _mm512_sub_pd(f[c], _mm512_mul_pd(g[c], Pr));
    // pressure_work_pair: Pr m_other (vij . g)
    const __m512d work =
        _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(vij[0], g[0]), _mm512_mul_pd(vij[1], g[1])), _mm512_mul_pd(vij[2], g[2]));
    _mm512_store_pd(work_i, _mm512_mul_pd(_mm512_mul_pd(Pr_to_i, mj), work));
    _mm512_store_pd(work_j, _mm512_mul_pd(_mm512_mul_pd(Pr_to_j, mi), work));
    for (std::size_t c = 0; c < 3; ++c) {
      _mm512_store_pd(to_i[c], _mm512_mul_pd(f[c], mj));
      _mm512_store_pd(to_j[c], _mm512_mul_pd(f[c], mi));
    }
    const std::size_t count = std::min<std::size_t>(8, n - q);
    for (std::size_t k = 0; k < count; ++k) {
      const std::uint32_t j = js[q + k];
      du_i += work_i[k];
      if constexpr (ArtificialViscosity) signal_i = std::max(signal_i, signal[k]);
      for (int c = 0; c < 3; ++c) ai[c] += to_i[c][k];
      if (j < d.writable) {
        if constexpr (ArtificialViscosity) d.signal_speed[j] = std::max(d.signal_speed[j], signal[k]);
        if (d.du_dt) d.du_dt[j] += work_j[k];
        for (int c = 0; c < 3; ++c) d.acc[j][c] -= to_j[c][k];
      }
    }
  }
  if (ArtificialViscosity && i < d.writable) d.signal_speed[i] = std::max(d.signal_speed[i], signal_i);
}

// contract(M, v) (core/vec.hpp) of eight pairs: row a is (M_a0 v_0 + M_a1 v_1) + M_a2 v_2.
[[gnu::target("avx512f"), gnu::always_inline]] inline void contract3(const __m512d M[9], const __m512d v[3], __m512d out[3]) {
  for (std::size_t a = 0; a < 3; ++a)
    out[a] = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(M[3 * a], v[0]), _mm512_mul_pd(M[3 * a + 1], v[1])),
                           _mm512_mul_pd(M[3 * a + 2], v[2]));
}

// 3D consistent divergence of eq. 6 (consistent_viscous_pair with linear_corrected_gradients and
// the ln rho_j - ln rho_i that log_rho holds) with the pressure force and its work, no artificial
// viscosity (force_list_terms<3, true, false, true>, list_sums.hpp), eight partners per round: both
// particles' terms formed for all eight with the scalar loop's operations in its order, then added
// pair by pair in list order as the scalar loop adds them (the viscous term, then the pressure's
// work and force).
[[gnu::target("avx512f,avx512vl")]] void consistent_pressure_force_list_avx512(const ForceListData<3>& d, std::uint32_t i,
                                                                               const std::uint32_t* js, const float* F,
                                                                               std::size_t n, Vec<3>& ai, double& du_i) {
  static_assert(sizeof(Mat<3, ReducedReal>) == 9 * sizeof(double), "stresses and corrections are read as nine doubles");
  const double* pos = reinterpret_cast<const double*>(d.pos);
  const double* vel = reinterpret_cast<const double*>(d.vel);
  const double* stress = reinterpret_cast<const double*>(d.stress);
  const double* correction = reinterpret_cast<const double*>(d.correction);
  __m512d xi[3], vi[3], Si[9], Ci[9];
  for (int c = 0; c < 3; ++c) xi[c] = _mm512_set1_pd(d.pos[i][c]), vi[c] = _mm512_set1_pd(d.vel[i][c]);
  for (std::size_t c = 0; c < 9; ++c) Si[c] = _mm512_set1_pd(d.stress[i].c[c]), Ci[c] = _mm512_set1_pd(d.correction[i].c[c]);
  const __m512d log_rho_i = _mm512_set1_pd(d.log_rho[i]), Vi = _mm512_set1_pd(d.volume[i]);
  const __m512d mi = _mm512_set1_pd(d.mass[i]), Pr_i = _mm512_set1_pd(d.p_over_rho2[i]);
  alignas(64) double to_i[3][8], to_j[3][8], press_i[3][8], press_j[3][8], work_i[8], work_j[8];
  for (std::size_t q = 0; q < n; q += 8) {
    const Round r = load_round(js, F, q, n);
    __m512d xj[3], vj[3], Sj[9], Cj[9];
    load_triples(pos, r.j, xj);
    load_triples(vel, r.j, vj);
    load_nines(stress, r.j, Sj);
    load_nines(correction, r.j, Cj);
    __m512d g[3], vij[3];
    for (std::size_t c = 0; c < 3; ++c) {
      g[c] = _mm512_mul_pd(_mm512_sub_pd(xi[c], xj[c]), r.f);
      vij[c] = _mm512_sub_pd(vi[c], vj[c]);
    }
    const __m512d dl = _mm512_sub_pd(avx512::load_singles(d.log_rho, r.j), log_rho_i);
    const __m512d Vj = avx512::load_singles(d.volume, r.j);
    __m512d Gi[3], Gj[3], Xi[9], Xj[9], ti[3], tj[3];
    contract3(Ci, g, Gi);
    contract3(Cj, g, Gj);
    for (std::size_t c = 0; c < 9; ++c) {
      const __m512d dS = _mm512_sub_pd(Sj[c], Si[c]);
      Xi[c] = _mm512_add_pd(dS, _mm512_mul_pd(Si[c], dl));
      Xj[c] = _mm512_add_pd(dS, _mm512_mul_pd(Sj[c], dl));
    }
    contract3(Xi, Gi, ti);
    contract3(Xj, Gj, tj);
    // pressure_pair, subtracted from a zero f, and pressure_work_pair with vij . g
    const __m512d mj = avx512::load_singles(d.mass, r.j), Pr_j = avx512::load_singles(d.p_over_rho2, r.j);
    const __m512d Pr = _mm512_add_pd(Pr_i, Pr_j);
    for (std::size_t c = 0; c < 3; ++c) {
      _mm512_store_pd(to_i[c], _mm512_mul_pd(ti[c], Vj));
      _mm512_store_pd(to_j[c], _mm512_mul_pd(tj[c], Vi));
      const __m512d f = _mm512_sub_pd(_mm512_setzero_pd(), _mm512_mul_pd(g[c], Pr));
      _mm512_store_pd(press_i[c], _mm512_mul_pd(f, mj));
      _mm512_store_pd(press_j[c], _mm512_mul_pd(f, mi));
    }
    const __m512d work =
        _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(vij[0], g[0]), _mm512_mul_pd(vij[1], g[1])), _mm512_mul_pd(vij[2], g[2]));
    _mm512_store_pd(work_i, _mm512_mul_pd(_mm512_mul_pd(Pr_i, mj), work));
    _mm512_store_pd(work_j, _mm512_mul_pd(_mm512_mul_pd(Pr_j, mi), work));
    const std::size_t count = std::min<std::size_t>(8, n - q);
    for (std::size_t k = 0; k < count; ++k) {
      const std::uint32_t j = js[q + k];
      const bool writable = j < d.writable;
      for (int c = 0; c < 3; ++c) ai[c] += to_i[c][k];
      if (writable)
        for (int c = 0; c < 3; ++c) d.acc[j][c] += to_j[c][k];
      du_i += work_i[k];
      if (writable && d.du_dt) d.du_dt[j] += work_j[k];
      for (int c = 0; c < 3; ++c) ai[c] += press_i[c][k];
      if (writable)
        for (int c = 0; c < 3; ++c) d.acc[j][c] -= press_j[c][k];
    }
  }
}
#endif

// CubicSpline::w (kernels.hpp) of eight q, its operations in its order:
// 0.25 ((2 - q)_+^3 - 4 (1 - q)_+^3).
[[gnu::target("avx512f"), gnu::always_inline]] inline __m512d cubic_w(__m512d q) {
  const __m512d one = _mm512_set1_pd(1.0), two = _mm512_set1_pd(2.0);
  const __m512d a = _mm512_maskz_sub_pd(_mm512_cmp_pd_mask(q, two, _CMP_LT_OQ), two, q);
  const __m512d b = _mm512_maskz_sub_pd(_mm512_cmp_pd_mask(q, one, _CMP_LT_OQ), one, q);
  const __m512d a3 = _mm512_mul_pd(_mm512_mul_pd(a, a), a);
  const __m512d b3 = _mm512_mul_pd(_mm512_mul_pd(_mm512_mul_pd(_mm512_set1_pd(4.0), b), b), b);
  return _mm512_mul_pd(_mm512_set1_pd(0.25), _mm512_sub_pd(a3, b3));
}

// The scatter density's pair terms (add_scatter_list_scalar, list_sums.hpp) with the cubic kernel in
// 2D, eight partners per round: distances, both kernel values (CubicSpline::w, kernels.hpp, with
// its operations in its order) and the mass-weighted terms formed for all eight, then added to i's
// sum and to the writable partners' pair by pair in list order.
[[gnu::target("avx512f,avx512vl")]] void scatter_list_avx512(const ScatterListData<2>& d, std::uint32_t i,
                                                             const std::uint32_t* js, std::size_t n, double& sum_i) {
  const double* pos = reinterpret_cast<const double*>(d.pos);
  static_assert(sizeof(KernelScale) == 2 * sizeof(double), "kernel scales are read as (1 / h, norm) pairs");
  const double* scales = reinterpret_cast<const double*>(d.scales);
  const __m512d xi = _mm512_set1_pd(d.pos[i][0]), yi = _mm512_set1_pd(d.pos[i][1]);
  const __m512d inv_h_i = _mm512_set1_pd(d.scales[i].inv_h), norm_i = _mm512_set1_pd(d.scales[i].w_norm);
  const __m512d mi = _mm512_set1_pd(d.mass[i]);
  alignas(64) double to_i[8], to_j[8];
  for (std::size_t q = 0; q < n; q += 8) {
    const std::size_t count = std::min<std::size_t>(8, n - q);
    const avx512::Round8 r = avx512::round8(js + q, count);
    __m512d xj, yj, inv_h_j, norm_j;
    avx512::load_pairs(pos, r, xj, yj);
    avx512::load_pairs(scales, r, inv_h_j, norm_j);
    const __m512d dist = _mm512_maskz_sqrt_pd(0xFF, avx512::squared_norms(_mm512_sub_pd(xi, xj), _mm512_sub_pd(yi, yj)));
    const __m512d Wi = _mm512_mul_pd(norm_i, cubic_w(_mm512_mul_pd(dist, inv_h_i)));
    const __m512d Wj = _mm512_mul_pd(norm_j, cubic_w(_mm512_mul_pd(dist, inv_h_j)));
    _mm512_store_pd(to_i, _mm512_mul_pd(avx512::load_singles(d.mass, r), Wj));
    _mm512_store_pd(to_j, _mm512_mul_pd(mi, Wi));
    for (std::size_t k = 0; k < count; ++k) {
      sum_i += to_i[k];
      const std::uint32_t j = js[q + k];
      if (j < d.writable) d.sums[j] += to_j[k];
    }
  }
}

// The scalar gradient loop compiled for AVX2: a pair's eight sums in two instructions, not four.
// (The force loop compiled so was slower; with AVX2 only it runs the scalar loop: docs/design.md,
// "Modes kept and retired".)
template <int D>
[[gnu::target("avx2")]] void gradient_list_avx2(const GradientListData<D>& d, std::uint32_t i, std::span<const std::uint32_t> js,
                                                std::span<const float> F, GradientSums<D>& sum_i) {
  add_gradient_list_scalar(d, i, js, F, sum_i);
}


#endif

}  // namespace

template <int D>
void add_gradient_list(const GradientListData<D>& d, std::uint32_t i, std::span<const std::uint32_t> js,
                       std::span<const float> F, GradientSums<D>& sum_i) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  if (d.scales) return add_gradient_list_scalar(d, i, js, F, sum_i);
  if (vector_isa() == VectorIsa::avx512) return gradient_list_avx512(d, i, js.data(), F.data(), js.size(), sum_i);
  if (vector_isa() == VectorIsa::avx2) return gradient_list_avx2(d, i, js, F, sum_i);
#endif
  add_gradient_list_scalar(d, i, js, F, sum_i);
}

template void add_gradient_list(const GradientListData<2>&, std::uint32_t, std::span<const std::uint32_t>,
                                std::span<const float>, GradientSums<2>&);
template void add_gradient_list(const GradientListData<3>&, std::uint32_t, std::span<const std::uint32_t>,
                                std::span<const float>, GradientSums<3>&);

template <int D>
void add_scatter_list(const ScatterListData<D>& d, std::uint32_t i, std::span<const std::uint32_t> js, double& sum_i) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  if constexpr (D == 2) {
    if (d.kernel == KernelType::Cubic && vector_isa() == VectorIsa::avx512) return scatter_list_avx512(d, i, js.data(), js.size(), sum_i);
  }
#endif
  with_kernel(d.kernel, [&](auto k) { add_scatter_list_scalar<decltype(k)>(d, i, js, sum_i); });
}

template void add_scatter_list(const ScatterListData<2>&, std::uint32_t, std::span<const std::uint32_t>, double&);
template void add_scatter_list(const ScatterListData<3>&, std::uint32_t, std::span<const std::uint32_t>, double&);

void add_force_list(const ForceListData<2>& d, std::uint32_t i, std::span<const std::uint32_t> js, std::span<const float> F,
                    Vec<2>& ai, double& du_i) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
#ifndef SPHDISK_SINGLE_PRECISION_FIELDS
  if (!d.force_correction && vector_isa() == VectorIsa::avx512) {
    if (!d.with_pressure && !d.consistent) return force_list_avx512(d, i, js.data(), F.data(), js.size(), ai);
    if (d.consistent && !d.rho_without_self && !d.correction_shift && !d.sound_speed) {
      if (d.with_pressure) return consistent_force_list_avx512<true>(d, i, js.data(), F.data(), js.size(), ai, du_i);
      return consistent_force_list_avx512<false>(d, i, js.data(), F.data(), js.size(), ai, du_i);
    }
  }
#endif
#endif
  add_force_list_scalar(d, i, js, F, ai, du_i);
}

void add_force_list(const ForceListData<3>& d, std::uint32_t i, std::span<const std::uint32_t> js, std::span<const float> F,
                    Vec<3>& ai, double& du_i) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
#ifndef SPHDISK_SINGLE_PRECISION_FIELDS
  if (d.with_pressure && !d.force_correction && !d.consistent && vector_isa() == VectorIsa::avx512) {
    if (d.sound_speed) return pressure_force_list_avx512<true>(d, i, js.data(), F.data(), js.size(), ai, du_i);
    return pressure_force_list_avx512<false>(d, i, js.data(), F.data(), js.size(), ai, du_i);
  }
  if (d.with_pressure && d.consistent && !d.rho_without_self && !d.correction_shift && !d.sound_speed &&
      vector_isa() == VectorIsa::avx512)
    return consistent_pressure_force_list_avx512(d, i, js.data(), F.data(), js.size(), ai, du_i);
#endif
#endif
  add_force_list_scalar(d, i, js, F, ai, du_i);
}

}  // namespace sphdisk
