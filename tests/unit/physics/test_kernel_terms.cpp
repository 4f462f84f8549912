// The h solve's kernel terms and their sums (physics/kernel_terms.hpp) must come out of the AVX2 and
// AVX-512 builds of the loops (those the CPU runs) bit for bit as out of the baseline one, for every
// kernel, at the kernels' breakpoints too (q = 1 and 2, where the selects switch), for lengths that
// leave remainders of every size, with equal masses factored out and with a mass per candidate; and
// the sums are those of the four interleaved partial sums in their documented order.
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
  std::vector<double> masses(dist.size());
  for (double& m : masses) m = 0.5 + r(rng);
  for (const double* mass : {static_cast<const double*>(nullptr), static_cast<const double*>(masses.data())})
  for (const double inv_h : {1.0, 0.93, 1.7}) {
    for (std::size_t n = 0; n <= dist.size(); n += 1) {
      std::vector<double> w1(n), dw1(n), w2(n), dw2(n);
      KernelSums s1{}, s2{};
      test::on_path(isa, [&] { return s1 = kernel_sums<K, D>(dist.data(), mass, inv_h, n, w1.data(), dw1.data()), 0; });
      test::on_path(VectorIsa::baseline, [&] { return s2 = kernel_sums<K, D>(dist.data(), mass, inv_h, n, w2.data(), dw2.data()), 0; });
      ASSERT_EQ(std::memcmp(w1.data(), w2.data(), n * sizeof(double)), 0) << vector_isa_name(isa) << " " << K::name << " n = " << n;
      ASSERT_EQ(std::memcmp(dw1.data(), dw2.data(), n * sizeof(double)), 0) << vector_isa_name(isa) << " " << K::name << " n = " << n;
      ASSERT_EQ(std::memcmp(&s1, &s2, sizeof s1), 0) << vector_isa_name(isa) << " " << K::name << " n = " << n;
      double sw[4] = {}, sdw[4] = {};  // the documented order, written out
      for (std::size_t k = 0; k < n; ++k) {  // and both are the kernel's own values
        const double q = dist[k] * inv_h;
        ASSERT_DOUBLE_EQ(w2[k], K::w(q));
        ASSERT_NEAR(dw2[k], D * K::w(q) + q * K::dw(q), 1e-14);
        const double m = mass ? mass[k] : 1.0;
        sw[k % 4] += m * w2[k];
        sdw[k % 4] += m * dw2[k];
      }
      ASSERT_EQ(s2.w, (sw[0] + sw[1]) + (sw[2] + sw[3])) << K::name << " n = " << n;
      ASSERT_EQ(s2.dw, (sdw[0] + sdw[1]) + (sdw[2] + sdw[3])) << K::name << " n = " << n;
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
