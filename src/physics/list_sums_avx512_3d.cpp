// The 3D AVX-512 bodies of the pair-list sums (list_sums_avx512.hpp).
#include "physics/list_sums_avx512.hpp"

// Compiled with -ffp-contract=off (src/CMakeLists.txt), as the scalar loops it must equal bit for bit.
#ifdef SPHDISK_X86_VECTOR_DISPATCH

namespace sphdisk::list_avx512 {

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

template void pressure_force_list_avx512<true>(const ForceListData<3>&, std::uint32_t, const std::uint32_t*, const float*,
                                               std::size_t, Vec<3>&, double&);
template void pressure_force_list_avx512<false>(const ForceListData<3>&, std::uint32_t, const std::uint32_t*, const float*,
                                                std::size_t, Vec<3>&, double&);

// contract(M, v) (core/vec.hpp) of eight pairs: row a is (M_a0 v_0 + M_a1 v_1) + M_a2 v_2.
[[gnu::target("avx512f"), gnu::always_inline]] inline void contract3(const __m512d M[9], const __m512d v[3], __m512d out[3]) {
  for (std::size_t a = 0; a < 3; ++a)
    out[a] = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(M[3 * a], v[0]), _mm512_mul_pd(M[3 * a + 1], v[1])),
                           _mm512_mul_pd(M[3 * a + 2], v[2]));
}

// 3D consistent divergence of eq. 6 (consistent_viscous_pair with linear_corrected_gradients and
// the ln rho_j - ln rho_i that log_rho holds) with the pressure force and its work, no artificial
// viscosity (force_list_terms<3, true, false, true>, list_sums.hpp), eight partners per round: both
// particles' terms formed for all eight with the scalar loop's operations in its order, i's added
// to its eight lanes of sums (lane_sums.hpp), each partner's added to it in list order, the lanes
// totalled at the end.
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
  __m512d lane[3] = {_mm512_setzero_pd(), _mm512_setzero_pd(), _mm512_setzero_pd()}, lane_du = _mm512_setzero_pd();
  alignas(64) double to_j[3][8], work_j[8];
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
    const std::size_t count = std::min<std::size_t>(8, n - q);
    const auto live = static_cast<__mmask8>((1u << count) - 1u);
    for (std::size_t c = 0; c < 3; ++c) {
      const __m512d f = _mm512_sub_pd(_mm512_setzero_pd(), _mm512_mul_pd(g[c], Pr));
      const __m512d to_i = _mm512_add_pd(_mm512_mul_pd(ti[c], Vj), _mm512_mul_pd(f, mj));
      lane[c] = _mm512_mask_add_pd(lane[c], live, lane[c], to_i);
      _mm512_store_pd(to_j[c], _mm512_sub_pd(_mm512_mul_pd(tj[c], Vi), _mm512_mul_pd(f, mi)));
    }
    const __m512d work =
        _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(vij[0], g[0]), _mm512_mul_pd(vij[1], g[1])), _mm512_mul_pd(vij[2], g[2]));
    lane_du = _mm512_mask_add_pd(lane_du, live, lane_du, _mm512_mul_pd(_mm512_mul_pd(Pr_i, mj), work));
    _mm512_store_pd(work_j, _mm512_mul_pd(_mm512_mul_pd(Pr_j, mi), work));
    for (std::size_t k = 0; k < count; ++k) {
      const std::uint32_t j = js[q + k];
      if (j >= d.writable) continue;
      for (int c = 0; c < 3; ++c) d.acc[j][c] += to_j[c][k];
      if (d.du_dt) d.du_dt[j] += work_j[k];
    }
  }
  for (int c = 0; c < 3; ++c) ai[c] += lane_total(lane[static_cast<std::size_t>(c)]);
  du_i += lane_total(lane_du);
}
#endif

}  // namespace sphdisk::list_avx512

#endif
