// The parallel layer: every index visited once, reductions and fork/join results independent of the
// thread count (bit for bit), tasks' results in task order.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "parallel/loops.hpp"

using namespace sphdisk;

TEST(ParallelLayer, ForEachVisitsEveryIndexOnce) {
  for (int threads : {1, 2, 3, 4}) {
    par::set_threads(threads);
    std::vector<int> hits(100003, 0);
    par::for_each(hits.size(), [&](std::size_t i) { hits[i] += 1; });
    for (int h : hits) ASSERT_EQ(h, 1);
  }
  par::set_threads(0);
}

TEST(ParallelLayer, PermutePrefixRearrangesThePrefixOnly) {
  // Longer than one work unit (4096), reversed so that every moved element lands elsewhere.
  const std::size_t n = 20000, m = 9001;
  std::vector<std::uint32_t> order(m);
  for (std::size_t k = 0; k < m; ++k) order[k] = static_cast<std::uint32_t>(m - 1 - k);
  for (int threads : {1, 3}) {
    par::set_threads(threads);
    std::vector<double> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<double>(i);
    par::permute_prefix(v, order);
    ASSERT_EQ(v.size(), n);
    for (std::size_t k = 0; k < m; ++k) ASSERT_EQ(v[k], static_cast<double>(m - 1 - k));
    for (std::size_t i = m; i < n; ++i) ASSERT_EQ(v[i], static_cast<double>(i));
  }
  par::set_threads(0);
}

TEST(ParallelLayer, SumIsBitIdenticalForAnyThreadCount) {
  // Terms of wildly different magnitude: any change of summation order changes the bits.
  auto term = [](std::size_t i) { return std::sin(static_cast<double>(i)) * std::pow(10.0, static_cast<double>(i % 17) - 8); };
  std::vector<double> sums;
  for (int threads : {1, 2, 3, 4}) {
    par::set_threads(threads);
    sums.push_back(par::sum<double>(1'000'003, term));
  }
  par::set_threads(0);
  for (double s : sums) EXPECT_EQ(s, sums[0]);
  // And the order is the documented one: blocks of kReduceBlock in index order.
  double expected = 0;
  for (std::size_t b = 0; b * par::kReduceBlock < 1'000'003; ++b) {
    double block = 0;
    for (std::size_t i = b * par::kReduceBlock; i < std::min<std::size_t>(1'000'003, (b + 1) * par::kReduceBlock); ++i) block += term(i);
    expected += block;
  }
  EXPECT_EQ(sums[0], expected);
}

TEST(ParallelLayer, MapTasksReturnsResultsInTaskOrder) {
  for (int threads : {1, 3}) {
    par::set_threads(threads);
    const auto r = par::map_tasks<long long>(50, [](std::size_t t) {
      long long s = 0;
      for (std::size_t k = 0; k < 1000 * (t % 7 + 1); ++k) s += static_cast<long long>(k * t);
      return s;
    });
    ASSERT_EQ(r.size(), 50u);
    for (std::size_t t = 0; t < 50; ++t) {
      long long s = 0;
      for (std::size_t k = 0; k < 1000 * (t % 7 + 1); ++k) s += static_cast<long long>(k * t);
      EXPECT_EQ(r[t], s);
    }
  }
  par::set_threads(0);
}

TEST(ParallelLayer, EmptyRangesAreFine) {
  par::for_each(0, [](std::size_t) { FAIL(); });
  EXPECT_EQ(par::sum<double>(0, [](std::size_t) { return 1.0; }), 0.0);
}
