#pragma once
// A particle's sum over one list kept in eight partial sums, partner q of the list adding to sum
// q mod 8, then totalled by a fixed tree: the order in which eight-wide vector loops add their
// rounds (one vector of sums, a lane per partner of the round), written once for the scalar loops
// so that both give the same bits. One running sum would chain every term on the previous one, and
// that chain, not the terms, bounds a vector loop (docs/performance.md, "The consistent viscous
// force").
#include <array>
#include <cstddef>

#include "core/vec.hpp"

namespace sphdisk {

constexpr std::size_t kLanes = 8;

struct LaneSum {
  std::array<double, kLanes> lane{};

  void add(std::size_t q, double x) { lane[q % kLanes] += x; }

  // ((l0 + l4) + (l2 + l6)) + ((l1 + l5) + (l3 + l7)): the upper half of eight added to the lower,
  // then the upper half of the four to the lower, then the two.
  double total() const {
    const double a0 = lane[0] + lane[4], a1 = lane[1] + lane[5], a2 = lane[2] + lane[6], a3 = lane[3] + lane[7];
    return (a0 + a2) + (a1 + a3);
  }
};

// A vector's components and one scalar (the force loop's acceleration and energy rate).
template <int D>
struct LaneSums {
  std::array<LaneSum, D> vec{};
  LaneSum scalar{};

  void add(std::size_t q, const Vec<D>& x) {
    for (int c = 0; c < D; ++c) vec[static_cast<std::size_t>(c)].add(q, x[c]);
  }
  void add(std::size_t q, double x) { scalar.add(q, x); }

  // The totals added to what the sums held before the list.
  void add_to(Vec<D>& v, double& s) const {
    for (int c = 0; c < D; ++c) v[c] += vec[static_cast<std::size_t>(c)].total();
    s += scalar.total();
  }
};

}  // namespace sphdisk
