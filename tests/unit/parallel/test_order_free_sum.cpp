// order_free_sums (parallel/order_free_sum.hpp): the same bits whatever the order of the values and
// the thread count (and so whatever their split over ranks, which only reorders the integer
// additions), signed values too, and the sum of the values to within one rounding where none lies
// below 2^-62 of the largest.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <random>
#include <vector>

#include "parallel/loops.hpp"
#include "parallel/order_free_sum.hpp"

namespace sphdisk {
namespace {

std::vector<double> masses_over_decades(std::size_t n) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> exponent(-6, 0);
  std::vector<double> m(n);
  for (double& v : m) v = 1e-10 * std::pow(10.0, exponent(rng));
  return m;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(OrderFreeSum, AnyOrderGivesTheSameBits) {
  std::vector<double> m = masses_over_decades(100000);
  const Communicator one = Communicator::self();
  const double total = order_free_sum(one, m);
  std::mt19937_64 rng(9);
  for (int k = 0; k < 5; ++k) {
    std::shuffle(m.begin(), m.end(), rng);
    EXPECT_TRUE(same_bits(order_free_sum(one, m), total));
  }
  // The plain sum in a different order differs in its last bits here (what the function avoids).
  const double forward = std::accumulate(m.begin(), m.end(), 0.0);
  const double backward = std::accumulate(m.rbegin(), m.rend(), 0.0);
  EXPECT_FALSE(same_bits(forward, backward));
}

TEST(OrderFreeSum, IsTheSumToOneRounding) {
  const std::vector<double> m = masses_over_decades(100000);
  long double exact = 0;  // 64-bit mantissa: exact enough to judge a double's rounding here
  for (double v : m) exact += v;
  const double total = order_free_sum(Communicator::self(), m);
  EXPECT_LE(std::fabs(static_cast<long double>(total) - exact), 1.0L * std::ldexp(1.0, std::ilogb(total) - 52));
  const std::vector<float> f = {1.5f, 0.25f, 3.0f};
  EXPECT_EQ(order_free_sum(Communicator::self(), f), 4.75);
  EXPECT_EQ(order_free_sum(Communicator::self(), std::vector<double>{}), 0.0);
  EXPECT_EQ(order_free_sum(Communicator::self(), std::vector<double>{3e-310, 1e-310}), 4e-310);  // subnormal
  const auto with_nan = order_free_sums<2>(Communicator::self(), 3, [](std::size_t i) {
    return std::array<double, 2>{1.0, i == 1 ? std::nan("") : 2.0};
  });
  EXPECT_EQ(with_nan[0], 3.0);
  EXPECT_TRUE(std::isnan(with_nan[1]));
}

TEST(OrderFreeSum, SignedSumsOfSeveralKindsAnyThreadCountAndOrder) {
  std::vector<double> m = masses_over_decades(50000);
  std::mt19937_64 rng(4);
  std::normal_distribution<double> gauss(0, 1);
  std::vector<double> signed_values(m.size());
  for (double& v : signed_values) v = 1e-3 * gauss(rng);
  auto sums = [&] {
    return order_free_sums<2>(Communicator::self(), m.size(),
                              [&](std::size_t i) { return std::array<double, 2>{m[i], signed_values[i]}; });
  };
  par::set_threads(1);
  const auto one = sums();
  for (int threads : {2, 3}) {
    par::set_threads(threads);
    const auto other = sums();
    EXPECT_TRUE(same_bits(other[0], one[0]) && same_bits(other[1], one[1])) << threads << " threads";
  }
  par::set_threads(0);
  std::vector<std::size_t> order(m.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  const auto shuffled = order_free_sums<2>(Communicator::self(), m.size(), [&](std::size_t i) {
    return std::array<double, 2>{m[order[i]], signed_values[order[i]]};
  });
  EXPECT_TRUE(same_bits(shuffled[0], one[0]) && same_bits(shuffled[1], one[1]));
  long double exact = 0;
  for (double v : signed_values) exact += v;
  // Two roundings of the total and each value's part below 2^-61 of the largest's power of two.
  double largest = 0;
  for (double v : signed_values) largest = std::max(largest, std::fabs(v));
  const double bound = std::ldexp(1.0, std::ilogb(one[1]) - 51) +
                       static_cast<double>(m.size()) * std::ldexp(1.0, std::ilogb(largest) - 61);
  EXPECT_LE(std::fabs(static_cast<long double>(one[1]) - exact), bound);
}

}  // namespace
}  // namespace sphdisk
