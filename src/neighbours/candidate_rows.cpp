// The ranges of slots of a point's rows of cells, in 2D or in 3D (candidate_ranges.hpp,
// row_ranges): row_range row by row, or, where the CPU has AVX-512, eight rows at once. Each row costs a square root,
// products, compares and two cell coordinates, and the search visits ~5 rows per particle
// (docs/performance.md, "Vector loops (AVX-512 and AVX2)"). Both paths give the same ranges bit for
// bit: the same operations in the same order, contraction off in this file (src/CMakeLists.txt),
// compared by the unit tests (CandidateRows.*).
#include <algorithm>
#include <cmath>

#include "core/vector_isa.hpp"
#include "neighbours/candidate_ranges.hpp"

#ifdef SPHDISK_X86_VECTOR_DISPATCH
#include <immintrin.h>
#endif

namespace sphdisk {

namespace {

// The n rows (ys[k], zs[k]) (zs unused in 2D).
template <int D>
void row_ranges_scalar(const CellGrid<D>& g, const RowSearch<D>& q, const int* ys, const int* zs, int n, std::uint32_t* s0,
                       std::uint32_t* s1) {
  std::array<int, D> cell = q.c;
  for (int k = 0; k < n; ++k) {
    cell[1] = ys[k];
    if constexpr (D == 3) cell[2] = zs[k];
    const auto [a, b] = row_range<D>(g, q, cell);
    s0[k] = a;
    s1[k] = b;
  }
}

#ifdef SPHDISK_X86_VECTOR_DISPATCH

// All lanes: the masked forms of the intrinsics below, as GCC 12's unmasked ones warn of their
// undefined pass-through vector (GCC bug 105593).
constexpr __mmask8 kAll = 0xFF;

// CellGrid::coord_in_cells along x for eight quotients t: floor(t) - origin, 0 below the grid (and
// for NaN), dims - 1 beyond it.
template <int D>
__attribute__((target("avx512f,avx512vl"))) __m256i coords_x(const CellGrid<D>& g, __m512d t) {
  const __m512d first = _mm512_set1_pd(g.origin[0]);
  const __m512d beyond = _mm512_set1_pd(g.origin[0] + g.dims[0]);  // first + dims, as coord_in_cells
  const __m512d whole = _mm512_maskz_roundscale_pd(kAll, t, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
  __m512d c = _mm512_sub_pd(whole, first);
  c = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(t, beyond, _CMP_GE_OQ), c, _mm512_set1_pd(g.dims[0] - 1));
  c = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(t, first, _CMP_NGE_UQ), c, _mm512_setzero_pd());
  return _mm512_maskz_cvttpd_epi32(kAll, c);
}

// The squared distances from x, past the margin, to eight bands of cells along axis k: the bands
// at coordinates c[0..8) (origin + c, as int), as row_range forms each.
template <int D>
__attribute__((target("avx512f,avx512vl"), always_inline)) inline __m512d band_distances2(const CellGrid<D>& g, const RowSearch<D>& q,
                                                                                        const int* c, int k) {
  const auto kk = static_cast<std::size_t>(k);
  const __m512d cs = _mm512_set1_pd(g.cell_size), xq = _mm512_set1_pd(q.x[k]), zero = _mm512_setzero_pd();
  const __m256i band = _mm256_add_epi32(_mm256_set1_epi32(g.origin[kk]), _mm256_loadu_si256(reinterpret_cast<const __m256i*>(c)));
  const __m512d lo = _mm512_add_pd(_mm512_set1_pd(g.lo[k]), _mm512_mul_pd(_mm512_maskz_cvtepi32_pd(kAll, band), cs));
  const __m512d d = _mm512_maskz_max_pd(kAll, _mm512_maskz_max_pd(kAll, _mm512_sub_pd(lo, xq), _mm512_sub_pd(xq, _mm512_add_pd(lo, cs))), zero);
  const __m512d dm = _mm512_maskz_max_pd(kAll, _mm512_sub_pd(d, _mm512_set1_pd(q.margin)), zero);
  return _mm512_mul_pd(dm, dm);
}

// Up to eight rows (ys[k], zs[k]), k < n (zs unused in 2D; both with eight readable entries): the
// band distances, chords and end cells as vectors, then the offsets loaded one by one (gathers are slow on AMD's AVX-512 CPUs:
// core/avx512_partner_loads.hpp). In 3D the rows of several layers share the vectors (a search of
// reach 1 visits three rows in each of three layers), each lane adding its layer's squared band
// distance along z to its row's along y, in row_range's order.
template <int D>
__attribute__((target("avx512f,avx512vl"))) void rows8(const CellGrid<D>& g, const RowSearch<D>& q, const int* ys, const int* zs,
                                                       int n, std::uint32_t* s0, std::uint32_t* s1) {
  const __m512d margin = _mm512_set1_pd(q.margin), r2 = _mm512_set1_pd(q.radius * q.radius);
  __m512d d2 = band_distances2<D>(g, q, ys, 1);
  if constexpr (D == 3) d2 = _mm512_add_pd(d2, band_distances2<D>(g, q, zs, 2));
  const __mmask8 within = _mm512_cmp_pd_mask(d2, r2, _CMP_NGE_UQ);  // row_range: not d2 >= r^2
  const __m512d half_chord = _mm512_add_pd(_mm512_maskz_sqrt_pd(within, _mm512_maskz_sub_pd(within, r2, d2)), margin);
  const __m512d x = _mm512_set1_pd(q.x[0]), lo0 = _mm512_set1_pd(g.lo[0]), inv = _mm512_set1_pd(q.inv_cell);
  const __m256i hi_cell = _mm256_min_epi32(_mm256_set1_epi32(q.x1),
                                           coords_x(g, _mm512_mul_pd(_mm512_sub_pd(_mm512_add_pd(x, half_chord), lo0), inv)));
  const __m256i lo_cell = _mm256_max_epi32(_mm256_set1_epi32(q.x0),
                                           coords_x(g, _mm512_mul_pd(_mm512_sub_pd(_mm512_sub_pd(x, half_chord), lo0), inv)));
  alignas(32) int hi[8], low[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(hi), hi_cell);
  _mm256_store_si256(reinterpret_cast<__m256i*>(low), lo_cell);
  const auto width = static_cast<std::size_t>(g.dims[0]);
  for (int k = 0; k < n; ++k) {
    if (!((within >> k) & 1u)) {
      s0[k] = s1[k] = 0;
      continue;
    }
    std::size_t layer = 0;  // the first cell of the row's layer (CellGrid::linear)
    if constexpr (D == 3) layer = static_cast<std::size_t>(zs[k]) * static_cast<std::size_t>(g.dims[1]);
    const std::size_t row = (layer + static_cast<std::size_t>(ys[k])) * width;
    bool own_row = q.after && ys[k] == q.c[1];
    if constexpr (D == 3) own_row = own_row && zs[k] == q.c[2];
    s1[k] = g.offsets[row + static_cast<std::size_t>(hi[k]) + 1];
    s0[k] = own_row ? *q.after + 1 : g.offsets[row + static_cast<std::size_t>(low[k])];
  }
}

template <int D>
__attribute__((target("avx512f,avx512vl"))) void row_ranges_avx512(const CellGrid<D>& g, const RowSearch<D>& q, const int* ys,
                                                                   const int* zs, int n, std::uint32_t* s0, std::uint32_t* s1) {
  for (int k = 0; k < n; k += 8) rows8<D>(g, q, ys + k, D == 3 ? zs + k : nullptr, std::min(8, n - k), s0 + k, s1 + k);
}

#endif

}  // namespace

void row_ranges(const CellGrid<2>& g, const RowSearch<2>& q, int y0, int y1, std::uint32_t* s0, std::uint32_t* s1) {
  std::array<int, kMaxRows> ys{};
  const int n = y1 - y0 + 1;
  for (int k = 0; k < n; ++k) ys[static_cast<std::size_t>(k)] = y0 + k;
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  if (vector_isa() == VectorIsa::avx512) return row_ranges_avx512<2>(g, q, ys.data(), nullptr, n, s0, s1);
#endif
  row_ranges_scalar<2>(g, q, ys.data(), nullptr, n, s0, s1);
}

void row_ranges(const CellGrid<3>& g, const RowSearch<3>& q, const int* ys, const int* zs, int n, std::uint32_t* s0,
                std::uint32_t* s1) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  if (vector_isa() == VectorIsa::avx512) return row_ranges_avx512<3>(g, q, ys, zs, n, s0, s1);
#endif
  row_ranges_scalar<3>(g, q, ys, zs, n, s0, s1);
}

}  // namespace sphdisk
