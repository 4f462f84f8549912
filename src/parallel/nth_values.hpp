#pragma once
// The values of given ranks in an unsorted array (rank k: what std::nth_element puts at index k),
// found in parallel (values finite, ranks below the size): a rank's value is unique, so it is the
// same for any thread count. Used for the quantiles of h that size the cells and tiles of every
// evaluation (evaluate/rate_evaluator.cpp), which a copy and std::nth_element would make on one thread
// while the others wait (docs/performance.md, "Serial passes and threads").
// How: values are bucketed by a monotone map of [min, max] onto kBuckets buckets (histograms of
// blocks in parallel), the bucket holding each rank is found from the counts, its values are
// collected (blocks in parallel, each to its place) and std::nth_element picks the rank among them.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "parallel/loops.hpp"

namespace sphdisk::par {

template <std::size_t N>
std::array<double, N> nth_values(const std::vector<double>& v, const std::array<std::size_t, N>& ranks) {
  constexpr std::size_t kBuckets = 4096;
  const std::size_t n = v.size();
  const std::size_t kBlock = std::max<std::size_t>(16384, n / 256 + 1);  // at most 256 histograms
  std::array<double, N> out{};
  if (n == 0) return out;
  struct Range {
    double lo, hi;
  };
  const Range r = reduce(n, Range{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()},
                         [&](std::size_t i) { return Range{v[i], v[i]}; },
                         [](Range a, Range b) { return Range{std::min(a.lo, b.lo), std::max(a.hi, b.hi)}; });
  if (!(r.lo < r.hi)) {  // all equal: every rank's value
    out.fill(r.lo);
    return out;
  }
  // Monotone in x: x - lo, the product by a positive constant and the truncation all keep order.
  const double scale = static_cast<double>(kBuckets) / (r.hi - r.lo);
  const auto bucket = [&](double x) { return std::min<std::size_t>(kBuckets - 1, static_cast<std::size_t>((x - r.lo) * scale)); };
  const std::size_t nblocks = (n + kBlock - 1) / kBlock;
  std::vector<std::uint32_t> counts(nblocks * kBuckets, 0);  // block b's histogram at b * kBuckets
  for_each(nblocks, [&](std::size_t b) {
    std::uint32_t* c = counts.data() + b * kBuckets;
    for (std::size_t i = b * kBlock, end = std::min(n, i + kBlock); i < end; ++i) ++c[bucket(v[i])];
  }, {}, 1);
  std::vector<std::size_t> total(kBuckets + 1, 0);  // values in buckets below each bucket
  for_each(kBuckets, [&](std::size_t k) {
    std::size_t sum = 0;
    for (std::size_t b = 0; b < nblocks; ++b) sum += counts[b * kBuckets + k];
    total[k + 1] = sum;
  }, {}, 512);
  for (std::size_t k = 0; k < kBuckets; ++k) total[k + 1] += total[k];
  for (std::size_t f = 0; f < N; ++f) {
    const std::size_t rank = ranks[f];
    const std::size_t k = static_cast<std::size_t>(std::upper_bound(total.begin(), total.end(), rank) - total.begin()) - 1;
    std::vector<std::size_t> at(nblocks + 1, 0);  // where each block's values of bucket k go
    for (std::size_t b = 0; b < nblocks; ++b) at[b + 1] = at[b] + counts[b * kBuckets + k];
    std::vector<double> in_bucket(at[nblocks]);
    for_each(nblocks, [&](std::size_t b) {
      std::size_t put = at[b];
      for (std::size_t i = b * kBlock, end = std::min(n, i + kBlock); i < end; ++i)
        if (bucket(v[i]) == k) in_bucket[put++] = v[i];
    }, {}, 1);
    const auto nth = in_bucket.begin() + static_cast<std::ptrdiff_t>(rank - total[k]);
    std::nth_element(in_bucket.begin(), nth, in_bucket.end());
    out[f] = *nth;
  }
  return out;
}

}  // namespace sphdisk::par
