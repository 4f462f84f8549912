// The h solve's kernel terms (physics/kernel_terms.hpp) must come out of the AVX2 and AVX-512 builds
// of the loop (those the CPU runs) bit for bit as out of the baseline one, for every kernel, at the kernels' breakpoints too
// (q = 1 and 2, where the selects switch), and for lengths that leave remainders of every size.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "core/vector_isa.hpp"
#include "physics/kernel_terms.hpp"
#include "physics/kernels.hpp"
#include "test_helpers.hpp"

using namespace sphdisk;

namespace {

template <class K, int D>
void check_paths_agree(VectorIsa isa) {
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
      test::on_path(isa, [&] { return kernel_terms<K, D>(dist.data(), inv_h, n, w1.data(), dw1.data()), 0; });
      test::on_path(VectorIsa::baseline, [&] { return kernel_terms<K, D>(dist.data(), inv_h, n, w2.data(), dw2.data()), 0; });
      ASSERT_EQ(std::memcmp(w1.data(), w2.data(), n * sizeof(double)), 0) << vector_isa_name(isa) << " " << K::name << " n = " << n;
      ASSERT_EQ(std::memcmp(dw1.data(), dw2.data(), n * sizeof(double)), 0) << vector_isa_name(isa) << " " << K::name << " n = " << n;
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
  if (test::vector_paths().empty()) GTEST_SKIP() << "this CPU has neither AVX2 nor AVX-512: only the baseline path runs";
  for (const VectorIsa isa : test::vector_paths()) {
    check_paths_agree<CubicSpline, 2>(isa);
    check_paths_agree<CubicSpline, 3>(isa);
    check_paths_agree<WendlandC2, 2>(isa);
    check_paths_agree<WendlandC4, 3>(isa);
  }
}
