// The 2D AVX-512 bodies of the pair-list sums (list_sums_avx512.hpp).
#include "physics/list_sums_avx512.hpp"

// Compiled with -ffp-contract=off (src/CMakeLists.txt), as the scalar loops it must equal bit for bit.
#ifdef SPHDISK_X86_VECTOR_DISPATCH

namespace sphdisk::list_avx512 {

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
// eight lanes of sums (lane_sums.hpp) and to the writable partners' in list order.
[[gnu::target("avx512f,avx512vl")]] void scatter_list_avx512(const ScatterListData<2>& d, std::uint32_t i,
                                                             const std::uint32_t* js, std::size_t n, double& sum_i) {
  const double* pos = reinterpret_cast<const double*>(d.pos);
  static_assert(sizeof(KernelScale) == 2 * sizeof(double), "kernel scales are read as (1 / h, norm) pairs");
  const double* scales = reinterpret_cast<const double*>(d.scales);
  const __m512d xi = _mm512_set1_pd(d.pos[i][0]), yi = _mm512_set1_pd(d.pos[i][1]);
  const __m512d inv_h_i = _mm512_set1_pd(d.scales[i].inv_h), norm_i = _mm512_set1_pd(d.scales[i].w_norm);
  const __m512d mi = _mm512_set1_pd(d.mass[i]);
  __m512d lanes = _mm512_setzero_pd();
  alignas(64) double to_j[8];
  for (std::size_t q = 0; q < n; q += 8) {
    const std::size_t count = std::min<std::size_t>(8, n - q);
    const avx512::Round8 r = avx512::round8(js + q, count);
    __m512d xj, yj, inv_h_j, norm_j;
    avx512::load_pairs(pos, r, xj, yj);
    avx512::load_pairs(scales, r, inv_h_j, norm_j);
    const __m512d dist = _mm512_maskz_sqrt_pd(0xFF, avx512::squared_norms(_mm512_sub_pd(xi, xj), _mm512_sub_pd(yi, yj)));
    const __m512d Wi = _mm512_mul_pd(norm_i, cubic_w(_mm512_mul_pd(dist, inv_h_i)));
    const __m512d Wj = _mm512_mul_pd(norm_j, cubic_w(_mm512_mul_pd(dist, inv_h_j)));
    const auto live = static_cast<__mmask8>((1u << count) - 1u);
    lanes = _mm512_mask_add_pd(lanes, live, lanes, _mm512_mul_pd(avx512::load_singles(d.mass, r), Wj));
    _mm512_store_pd(to_j, _mm512_mul_pd(mi, Wi));
    for (std::size_t k = 0; k < count; ++k) {
      const std::uint32_t j = js[q + k];
      if (j < d.writable) d.sums[j] += to_j[k];
    }
  }
  sum_i += lane_total(lanes);
}

#ifndef SPHDISK_SINGLE_PRECISION_FIELDS  // (stresses stored as double)
// A round's pair accelerations ((x, y) per pair in to_i and to_j) added to i's sum and subtracted
// from the writable partners' accelerations, pair by pair in list order (SSE2).
[[gnu::always_inline]] inline void add_round(const ForceListData<2>& d, const std::uint32_t* js, std::size_t count,
                                             const double* to_i, const double* to_j, __m128d& sum) {
  for (std::size_t k = 0; k < count; ++k) {
    sum = _mm_add_pd(sum, _mm_load_pd(to_i + 2 * k));
    const std::uint32_t j = js[k];
    if (j < d.writable) {
      double* a = d.acc[j].c.data();
      const __m128d t = _mm_load_pd(to_j + 2 * k);
      _mm_storeu_pd(a, _mm_sub_pd(_mm_loadu_pd(a), t));
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
    add_round(d, js + q, std::min<std::size_t>(8, n - q), to_i, to_j, sum);
  }
  _mm_storeu_pd(ai.c.data(), sum);
}

// The consistent divergence of eq. 6 (consistent_viscous_pair with linear_corrected_gradients and
// the ln rho_j - ln rho_i that log_rho holds), with the pressure force and its work where Pressure
// (no artificial viscosity; force_list_terms<2, Pressure, false, true>, list_sums.hpp), eight
// partners per round: both particles' terms formed for all eight with the scalar loop's operations
// in its order, i's added to its eight lanes of sums (lane_sums.hpp), each partner's added to it in
// list order, the lanes totalled at the end.
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
  __m512d lane_x = _mm512_setzero_pd(), lane_y = _mm512_setzero_pd(), lane_du = _mm512_setzero_pd();
  alignas(64) double to_j[16], work_j[8];
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
    __m512d ax = _mm512_mul_pd(_mm512_add_pd(_mm512_mul_pd(Xi[0], Gix), _mm512_mul_pd(Xi[1], Giy)), Vj);
    __m512d ay = _mm512_mul_pd(_mm512_add_pd(_mm512_mul_pd(Xi[2], Gix), _mm512_mul_pd(Xi[3], Giy)), Vj);
    __m512d bx = _mm512_mul_pd(_mm512_add_pd(_mm512_mul_pd(Xj[0], Gjx), _mm512_mul_pd(Xj[1], Gjy)), Vi);
    __m512d by = _mm512_mul_pd(_mm512_add_pd(_mm512_mul_pd(Xj[2], Gjx), _mm512_mul_pd(Xj[3], Gjy)), Vi);
    const std::size_t count = std::min<std::size_t>(8, n - q);
    const auto live = static_cast<__mmask8>((1u << count) - 1u);
    if constexpr (Pressure) {
      // pressure_pair, subtracted from a zero f, and pressure_work_pair with v_ij . g
      const __m512d mj = avx512::load_singles(d.mass, r.j), Pr_j = avx512::load_singles(d.p_over_rho2, r.j);
      const __m512d Pr = _mm512_add_pd(Pr_i, Pr_j);
      const __m512d fx = _mm512_sub_pd(_mm512_setzero_pd(), _mm512_mul_pd(gx, Pr));
      const __m512d fy = _mm512_sub_pd(_mm512_setzero_pd(), _mm512_mul_pd(gy, Pr));
      ax = _mm512_add_pd(ax, _mm512_mul_pd(fx, mj)), ay = _mm512_add_pd(ay, _mm512_mul_pd(fy, mj));
      bx = _mm512_sub_pd(bx, _mm512_mul_pd(fx, mi)), by = _mm512_sub_pd(by, _mm512_mul_pd(fy, mi));
      __m512d vxj, vyj;
      avx512::load_pairs(vel, r.j, vxj, vyj);
      const __m512d work = _mm512_add_pd(_mm512_mul_pd(_mm512_sub_pd(vxi, vxj), gx), _mm512_mul_pd(_mm512_sub_pd(vyi, vyj), gy));
      lane_du = _mm512_mask_add_pd(lane_du, live, lane_du, _mm512_mul_pd(_mm512_mul_pd(Pr_i, mj), work));
      _mm512_store_pd(work_j, _mm512_mul_pd(_mm512_mul_pd(Pr_j, mi), work));
    }
    lane_x = _mm512_mask_add_pd(lane_x, live, lane_x, ax);
    lane_y = _mm512_mask_add_pd(lane_y, live, lane_y, ay);
    interleave(bx, by, to_j);
    for (std::size_t k = 0; k < count; ++k) {
      const std::uint32_t j = js[q + k];
      if (j >= d.writable) continue;
      double* a = d.acc[j].c.data();
      _mm_storeu_pd(a, _mm_add_pd(_mm_loadu_pd(a), _mm_load_pd(to_j + 2 * k)));
      if (Pressure && d.du_dt) d.du_dt[j] += work_j[k];
    }
  }
  ai[0] += lane_total(lane_x);
  ai[1] += lane_total(lane_y);
  du_i += lane_total(lane_du);
}

template void consistent_force_list_avx512<true>(const ForceListData<2>&, std::uint32_t, const std::uint32_t*, const float*,
                                                 std::size_t, Vec<2>&, double&);
template void consistent_force_list_avx512<false>(const ForceListData<2>&, std::uint32_t, const std::uint32_t*, const float*,
                                                  std::size_t, Vec<2>&, double&);
#endif

}  // namespace sphdisk::list_avx512

#endif
