#pragma once
// Sums of values spread over threads and ranks with the same bits for any thread count, rank count
// and order of the values: each value is cut into two signed integer parts of 31 bits on a grid set
// by the largest magnitude of its kind, the parts are summed exactly as integers (in any order), and
// the two totals are rounded to a double once. Values below 2^-62 of the largest are lost; the rest
// enter exactly. A kind with a non-finite value sums to NaN.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "parallel/communicator.hpp"
#include "parallel/loops.hpp"

namespace sphdisk {

// K sums over items 0 .. n-1 of this rank (all ranks together): terms(i) gives item i's K values.
// Collective.
template <std::size_t K, class Terms>
std::array<double, K> order_free_sums(const Communicator& comm, std::size_t n, Terms terms) {
  using Values = std::array<double, K>;
  const auto larger = [](Values a, const Values& b) {
    for (std::size_t k = 0; k < K; ++k) a[k] = std::max(a[k], b[k]);
    return a;
  };
  Values largest = par::reduce(n, Values{}, [&](std::size_t i) {
    Values v = terms(i);
    for (double& x : v) x = std::isfinite(x) ? std::fabs(x) : HUGE_VAL;  // a NaN as infinite: max keeps it
    return v;
  }, larger);
  comm.max(std::span<double>(largest));
  Values total{};
  for (std::size_t k = 0; k < K; ++k)
    if (!std::isfinite(largest[k])) total[k] = std::numeric_limits<double>::quiet_NaN();  // (a failing run's)
  // Scaled by 2^(30 - e), each value's magnitude lies below 2^31; 2^31 values' parts sum below 2^62.
  std::array<int, K> e{};
  Values scale{};
  for (std::size_t k = 0; k < K; ++k) {
    e[k] = largest[k] > 0 && std::isfinite(largest[k]) ? std::ilogb(largest[k]) : 0;
    scale[k] = std::ldexp(1.0, 30 - e[k]);
  }
  constexpr double kLower = 2147483648.0;  // 2^31
  using Parts = std::array<std::int64_t, 2 * K>;
  Parts parts = par::reduce(n, Parts{}, [&](std::size_t i) {
    const Values v = terms(i);
    Parts q{};
    // Products with powers of two and differences of a value and its whole part are exact; the
    // conversions truncate toward zero. (Below 2^-960 a power of two as a double would overflow.)
    for (std::size_t k = 0; k < K; ++k) {
      if (!std::isfinite(largest[k])) continue;
      const double scaled = e[k] > -960 ? v[k] * scale[k] : std::ldexp(v[k], 30 - e[k]);
      const auto whole = static_cast<std::int64_t>(scaled);
      q[2 * k] = whole;
      q[2 * k + 1] = static_cast<std::int64_t>((scaled - static_cast<double>(whole)) * kLower);
    }
    return q;
  }, [](Parts a, const Parts& b) {
    for (std::size_t j = 0; j < 2 * K; ++j) a[j] += b[j];
    return a;
  });
  // Over ranks as unsigned integers: two's complement sums wrap to the same bits as signed ones.
  std::array<std::uint64_t, 2 * K> wide{};
  for (std::size_t j = 0; j < 2 * K; ++j) wide[j] = static_cast<std::uint64_t>(parts[j]);
  comm.sum(std::span<std::uint64_t>(wide));
  for (std::size_t k = 0; k < K; ++k)
    if (std::isfinite(largest[k]))
      total[k] = std::ldexp(static_cast<double>(static_cast<std::int64_t>(wide[2 * k])), e[k] - 30) +
               std::ldexp(static_cast<double>(static_cast<std::int64_t>(wide[2 * k + 1])), e[k] - 61);
  return total;
}

// One such sum of a vector's values.
template <class T>
double order_free_sum(const Communicator& comm, const std::vector<T>& values) {
  return order_free_sums<1>(comm, values.size(), [&](std::size_t i) { return std::array<double, 1>{static_cast<double>(values[i])}; })[0];
}

}  // namespace sphdisk
