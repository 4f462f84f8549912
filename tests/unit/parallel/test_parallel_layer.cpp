// The parallel layer: every index visited once, reductions and fork/join results independent of the
// thread count (bit for bit), tasks' results in task order.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "core/overwrite_vector.hpp"
#include "core/vec.hpp"
#include "parallel/loops.hpp"
#include "parallel/nth_values.hpp"

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

TEST(ParallelLayer, PermutePrefixMovesRecordsWhole) {
  // Records of several doubles (as positions and stresses) through the raw buffer.
  const std::vector<std::uint32_t> order = {2, 0, 1};
  std::vector<Vec<2>> v = {Vec<2>{{1, 2}}, Vec<2>{{3, 4}}, Vec<2>{{5, 6}}, Vec<2>{{7, 8}}};
  par::permute_prefix(v, order);
  EXPECT_EQ(v[0], (Vec<2>{{5, 6}}));
  EXPECT_EQ(v[1], (Vec<2>{{1, 2}}));
  EXPECT_EQ(v[2], (Vec<2>{{3, 4}}));
  EXPECT_EQ(v[3], (Vec<2>{{7, 8}}));
  // Wider than a word (moved a word at a time) and not a whole number of words (moved whole).
  std::vector<std::array<double, 4>> t = {{1, 2, 3, 4}, {5, 6, 7, 8}, {9, 10, 11, 12}, {13, 14, 15, 16}};
  par::permute_prefix(t, order);
  EXPECT_EQ(t, (std::vector<std::array<double, 4>>{{9, 10, 11, 12}, {1, 2, 3, 4}, {5, 6, 7, 8}, {13, 14, 15, 16}}));
  std::vector<std::array<float, 3>> f = {{1, 2, 3}, {4, 5, 6}, {7, 8, 9}, {10, 11, 12}};
  par::permute_prefix(f, order);
  EXPECT_EQ(f, (std::vector<std::array<float, 3>>{{7, 8, 9}, {1, 2, 3}, {4, 5, 6}, {10, 11, 12}}));
}

TEST(ParallelLayer, PermutePrefixThroughOneScratchServesFieldsOfEveryWidth) {
  // The run's reorder: a whole permutation of fields of different widths through one scratch of
  // the widest field's size, left with what the scratch-owning form gives.
  const std::size_t n = 10001;
  std::vector<std::uint32_t> order(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = static_cast<std::uint32_t>((k * 7919) % n);  // 7919 prime to n
  std::vector<double> a(n);
  std::vector<std::array<double, 4>> b(n);
  for (std::size_t i = 0; i < n; ++i) {
    a[i] = static_cast<double>(i);
    b[i] = {static_cast<double>(i), 1.0, 2.0, -static_cast<double>(i)};
  }
  const auto a_alone = [&] { auto v = a; par::permute_prefix(v, order); return v; }();
  const auto b_alone = [&] { auto v = b; par::permute_prefix(v, order); return v; }();
  for (int threads : {1, 3}) {
    par::set_threads(threads);
    auto a2 = a;
    auto b2 = b;
    UnsetVector<std::byte> scratch(n * sizeof(b[0]));
    par::permute_prefix(a2, order, scratch);
    par::permute_prefix(b2, order, scratch);
    EXPECT_EQ(a2, a_alone);
    EXPECT_EQ(b2, b_alone);
    for (std::size_t k = 0; k < n; ++k) ASSERT_EQ(a2[k], static_cast<double>(order[k]));
  }
  par::set_threads(0);
}

TEST(ParallelLayer, PrefixOffsetsSumTheCounts) {
  for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{4095}, std::size_t{4096}, std::size_t{10001}}) {
    const auto count = [](std::size_t k) { return (k * 7919) % 13; };
    for (int threads : {1, 3}) {
      par::set_threads(threads);
      OverwriteVector<std::size_t> offsets(5, 99);  // stale entries from before are overwritten
      par::prefix_offsets(n, count, offsets);
      ASSERT_EQ(offsets.size(), n + 1);
      std::size_t sum = 0;
      ASSERT_EQ(offsets[0], 0u);
      for (std::size_t k = 0; k < n; ++k) {
        sum += count(k);
        ASSERT_EQ(offsets[k + 1], sum) << "n " << n << ", k " << k;
      }
    }
  }
  par::set_threads(0);
}

// The ranks' values equal std::nth_element's on a copy, for distributions that fill the buckets
// evenly, crowd them into one (a far outlier), repeat values, or hold one value.
TEST(ParallelLayer, NthValuesAreThoseOfNthElement) {
  std::mt19937_64 rng(71);
  std::uniform_real_distribution<double> u(0.5, 2.0);
  std::lognormal_distribution<double> wide(0.0, 1.0);
  std::vector<std::vector<double>> cases;
  cases.push_back({});
  cases.back().resize(100000);
  for (double& x : cases.back()) x = u(rng);
  cases.push_back(std::vector<double>(70001));
  for (double& x : cases.back()) x = wide(rng);
  cases.back()[123] = 1e6;  // nearly everything in the first bucket
  cases.push_back(std::vector<double>(50000));
  for (double& x : cases.back()) x = std::floor(u(rng) * 4.0);  // four values, many times each
  cases.push_back(std::vector<double>(1000, 0.25));
  cases.push_back({3.0});
  cases.push_back({2.0, 1.0});
  for (const std::vector<double>& v : cases) {
    const std::size_t n = v.size();
    const std::array<std::size_t, 4> ranks = {0, n / 2, (99 * n) / 100, n - 1};
    std::array<double, 4> expected{};
    for (std::size_t f = 0; f < ranks.size(); ++f) {
      std::vector<double> copy(v);
      std::nth_element(copy.begin(), copy.begin() + static_cast<std::ptrdiff_t>(ranks[f]), copy.end());
      expected[f] = copy[ranks[f]];
    }
    for (int threads : {1, 2, 4}) {
      par::set_threads(threads);
      EXPECT_EQ(par::nth_values(v, ranks), expected) << "n " << n << ", " << threads << " threads";
    }
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
