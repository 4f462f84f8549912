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

// ((l0 + l4) + (l2 + l6)) + ((l1 + l5) + (l3 + l7)): the upper half of eight added to the lower,
// then the upper half of the four to the lower, then the two.
inline double lane_total(const std::array<double, kLanes>& l) {
  const double a0 = l[0] + l[4], a1 = l[1] + l[5], a2 = l[2] + l[6], a3 = l[3] + l[7];
  return (a0 + a2) + (a1 + a3);
}

template <int D>
struct LaneSums {
  std::array<std::array<double, kLanes>, D> vec{};  // per component
  std::array<double, kLanes> scalar{};

  void add(std::size_t q, const Vec<D>& x) {
    for (int c = 0; c < D; ++c) vec[static_cast<std::size_t>(c)][q % kLanes] += x[c];
  }
  void add(std::size_t q, double x) { scalar[q % kLanes] += x; }

  // The totals added to what the sums held before the list.
  void add_to(Vec<D>& v, double& s) const {
    for (int c = 0; c < D; ++c) v[c] += lane_total(vec[static_cast<std::size_t>(c)]);
    s += lane_total(scalar);
  }
};

}  // namespace sphdisk
