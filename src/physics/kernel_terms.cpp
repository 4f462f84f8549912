#include "physics/kernel_terms.hpp"

#include <cmath>

#include "core/vector_isa.hpp"
#include "physics/kernels.hpp"

// Compiled with -ffp-contract=off (src/CMakeLists.txt): the AVX-512 build of the loop could fuse
// D w + q w' where the baseline one cannot, and all builds must give the same bits.
namespace sphdisk {

namespace {

template <class K, int D>
[[gnu::always_inline]] inline void terms(const double* __restrict dist, double inv_h, std::size_t n, double* __restrict w,
                                         double* __restrict dw) {
  for (std::size_t k = 0; k < n; ++k) {
    const double q = dist[k] * inv_h, wk = K::w(q);
    w[k] = wk;
    dw[k] = D * wk + q * K::dw(q);
  }
}

// Four doubles, one per partial sum (GCC's vector extension: element-wise IEEE operations, one
// instruction with AVX2 or AVX-512, two with the baseline's SSE2).
using Lanes4 = double __attribute__((vector_size(4 * sizeof(double))));

// Adds four consecutive doubles (times four consecutive masses, if given) to sum, lane by lane.
// (By reference: a vector returned by value without AVX would warn of an ABI change.)
[[gnu::always_inline]] inline void add4(Lanes4& sum, const double* a, const double* m) {
  Lanes4 v;
  __builtin_memcpy(&v, a, sizeof v);
  if (m) {
    Lanes4 mv;
    __builtin_memcpy(&mv, m, sizeof mv);
    v = mv * v;
  }
  sum += v;
}

template <class K, int D>
[[gnu::always_inline]] inline KernelSums sums(const double* __restrict dist, const double* __restrict mass, double inv_h,
                                              std::size_t n, double* __restrict w, double* __restrict dw) {
  terms<K, D>(dist, inv_h, n, w, dw);
  Lanes4 sw{}, sdw{};
  std::size_t k = 0;
  if (mass) {
    for (; k + 4 <= n; k += 4) {
      add4(sw, w + k, mass + k);
      add4(sdw, dw + k, mass + k);
    }
    for (int l = 0; k < n; ++k, ++l) {
      sw[l] += mass[k] * w[k];
      sdw[l] += mass[k] * dw[k];
    }
  } else {
    for (; k + 4 <= n; k += 4) {
      add4(sw, w + k, nullptr);
      add4(sdw, dw + k, nullptr);
    }
    for (int l = 0; k < n; ++k, ++l) {
      sw[l] += w[k];
      sdw[l] += dw[k];
    }
  }
  return {(sw[0] + sw[1]) + (sw[2] + sw[3]), (sdw[0] + sdw[1]) + (sdw[2] + sdw[3])};
}

template <class K, int D>
KernelSums sums_baseline(const double* dist, const double* mass, double inv_h, std::size_t n, double* w, double* dw) {
  return sums<K, D>(dist, mass, inv_h, n, w, dw);
}

[[gnu::always_inline]] inline void roots(const double* __restrict dist2, std::size_t n, double* __restrict dist) {
  for (std::size_t k = 0; k < n; ++k) dist[k] = std::sqrt(dist2[k]);
}

#ifdef SPHDISK_X86_VECTOR_DISPATCH
[[gnu::target("avx512f")]] void roots_avx512(const double* dist2, std::size_t n, double* dist) { roots(dist2, n, dist); }
[[gnu::target("avx2")]] void roots_avx2(const double* dist2, std::size_t n, double* dist) { roots(dist2, n, dist); }

template <class K, int D>
[[gnu::target("avx512f")]] KernelSums sums_avx512(const double* dist, const double* mass, double inv_h, std::size_t n,
                                                  double* w, double* dw) {
  return sums<K, D>(dist, mass, inv_h, n, w, dw);
}

template <class K, int D>
[[gnu::target("avx2")]] KernelSums sums_avx2(const double* dist, const double* mass, double inv_h, std::size_t n, double* w,
                                             double* dw) {
  return sums<K, D>(dist, mass, inv_h, n, w, dw);
}

#endif

}  // namespace

template <class K, int D>
KernelSums kernel_sums(const double* dist, const double* mass, double inv_h, std::size_t n, double* w, double* dw) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  switch (vector_isa()) {
    case VectorIsa::avx512: return sums_avx512<K, D>(dist, mass, inv_h, n, w, dw);
    case VectorIsa::avx2: return sums_avx2<K, D>(dist, mass, inv_h, n, w, dw);
    case VectorIsa::baseline: break;
  }
#endif
  return sums_baseline<K, D>(dist, mass, inv_h, n, w, dw);
}

void square_roots(const double* dist2, std::size_t n, double* dist) {
#ifdef SPHDISK_X86_VECTOR_DISPATCH
  switch (vector_isa()) {
    case VectorIsa::avx512: return roots_avx512(dist2, n, dist);
    case VectorIsa::avx2: return roots_avx2(dist2, n, dist);
    case VectorIsa::baseline: break;
  }
#endif
  roots(dist2, n, dist);
}

#define SPHDISK_KERNEL_TERMS(K)                                                                  \
  template KernelSums kernel_sums<K, 1>(const double*, const double*, double, std::size_t, double*, double*); \
  template KernelSums kernel_sums<K, 2>(const double*, const double*, double, std::size_t, double*, double*); \
  template KernelSums kernel_sums<K, 3>(const double*, const double*, double, std::size_t, double*, double*);
SPHDISK_KERNEL_TERMS(CubicSpline)
SPHDISK_KERNEL_TERMS(WendlandC2)
SPHDISK_KERNEL_TERMS(WendlandC4)
#undef SPHDISK_KERNEL_TERMS

}  // namespace sphdisk
