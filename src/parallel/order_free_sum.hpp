#pragma once
// The sum of non-negative values spread over ranks with the same bits for any rank count and any
// order of the values: each is cut into two integer parts of 31 bits on a grid set by the largest
// value, the parts are summed exactly as integers, and the two totals are rounded to a double once.
// Values below 2^-62 of the largest are lost; the rest enter exactly.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "parallel/communicator.hpp"

namespace sphdisk {

template <class T>
double order_free_sum(const Communicator& comm, const std::vector<T>& values) {
  double largest = 0;
  for (T v : values) largest = std::max(largest, static_cast<double>(v));
  largest = comm.max(largest);
  if (!(largest > 0)) return 0;
  // Scaled by 2^(30 - e), each value lies below 2^31; 2^31 values' parts sum below 2^62.
  const int e = std::ilogb(largest);
  std::uint64_t parts[2] = {0, 0};
  for (T v : values) {
    const double scaled = std::ldexp(static_cast<double>(v), 30 - e);  // exact: a power of two
    const double whole = std::floor(scaled);
    parts[0] += static_cast<std::uint64_t>(whole);
    parts[1] += static_cast<std::uint64_t>(std::floor(std::ldexp(scaled - whole, 31)));  // both exact
  }
  comm.sum(std::span<std::uint64_t>(parts));
  return std::ldexp(static_cast<double>(parts[0]), e - 30) + std::ldexp(static_cast<double>(parts[1]), e - 61);
}

}  // namespace sphdisk
