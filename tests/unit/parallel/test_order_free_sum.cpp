// order_free_sum (parallel/order_free_sum.hpp): the same bits whatever the order of the values (and
// so whatever their split over ranks, which only reorders the integer additions), and the sum of
// the values to within one rounding where none lies below 2^-62 of the largest.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <random>
#include <vector>

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
}

}  // namespace
}  // namespace sphdisk
