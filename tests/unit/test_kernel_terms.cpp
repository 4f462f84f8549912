// The h solve's kernel terms (physics/kernel_terms.hpp) must come out of the AVX-512 build of the
// loop bit for bit as out of the baseline one, for every kernel, at the kernels' breakpoints too
// (q = 1 and 2, where the selects switch), and for lengths that leave remainders of every size.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "core/vector_isa.hpp"
#include "physics/kernel_terms.hpp"
#include "physics/kernels.hpp"

using namespace sphdisk;

namespace {

template <class K, int D>
void check_paths_agree() {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> r(0.0, 2.5);
  std::vector<double> dist(67);
  for (double& d : dist) d = r(rng);
  dist[3] = 1.0;  // q = 1 and 2 exactly with inv_h = 1
  dist[4] = 2.0;
  dist[5] = 0.0;
  for (const double inv_h : {1.0, 0.93, 1.7}) {
    for (std::size_t n = 0; n <= dist.size(); n += 1) {
      std::vector<double> w1(n), dw1(n), w2(n), dw2(n);
      kernel_terms<K, D>(dist.data(), inv_h, n, w1.data(), dw1.data());
      allow_avx512(false);
      kernel_terms<K, D>(dist.data(), inv_h, n, w2.data(), dw2.data());
      allow_avx512(true);
      ASSERT_EQ(std::memcmp(w1.data(), w2.data(), n * sizeof(double)), 0) << K::name << " n = " << n;
      ASSERT_EQ(std::memcmp(dw1.data(), dw2.data(), n * sizeof(double)), 0) << K::name << " n = " << n;
      for (std::size_t k = 0; k < n; ++k) {  // and both are the kernel's own values
        const double q = dist[k] * inv_h;
        ASSERT_DOUBLE_EQ(w2[k], K::w(q));
        ASSERT_NEAR(dw2[k], D * K::w(q) + q * K::dw(q), 1e-14);
      }
    }
  }
}

}  // namespace

TEST(KernelTerms, AvxAndBaselinePathsAgree) {
  if (!use_avx512()) GTEST_SKIP() << "this CPU has no AVX-512: only the baseline path runs";
  check_paths_agree<CubicSpline, 2>();
  check_paths_agree<CubicSpline, 3>();
  check_paths_agree<WendlandC2, 2>();
  check_paths_agree<WendlandC4, 3>();
}
