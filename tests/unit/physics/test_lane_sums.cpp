// The eight-lane sums of a list (physics/lane_sums.hpp): partner q goes to lane q mod 8 and the
// lanes are totalled by the fixed tree the vector loops use; values whose sum depends on the order
// tell that order from others.
#include <gtest/gtest.h>

#include <vector>

#include "physics/lane_sums.hpp"

namespace sphdisk {
namespace {

TEST(LaneSums, PartnerQGoesToLaneQModEight) {
  LaneSum s;
  for (std::size_t q = 0; q < 20; ++q) s.add(q, static_cast<double>(q));
  // lanes 0-3 hold q, q + 8, q + 16; lanes 4-7 hold q, q + 8
  EXPECT_EQ(s.lane[0], 0.0 + 8.0 + 16.0);
  EXPECT_EQ(s.lane[3], 3.0 + 11.0 + 19.0);
  EXPECT_EQ(s.lane[4], 4.0 + 12.0);
  EXPECT_EQ(s.lane[7], 7.0 + 15.0);
  EXPECT_EQ(s.total(), 190.0);  // exact integers: any order gives the sum
}

TEST(LaneSums, TotalIsTheFixedTree) {
  // ((l0 + l4) + (l2 + l6)) + ((l1 + l5) + (l3 + l7)): 1e16 + 1 rounds to 1e16, so each order of
  // these lanes gives its own total.
  LaneSum s;
  const std::vector<double> lanes{1e16, 1.0, 1.0, 1.0, 1.0, 1.0, -1e16, 1.0};
  for (std::size_t q = 0; q < lanes.size(); ++q) s.add(q, lanes[q]);
  const double a0 = 1e16 + 1.0, a1 = 1.0 + 1.0, a2 = 1.0 + -1e16, a3 = 1.0 + 1.0;
  EXPECT_EQ(s.total(), (a0 + a2) + (a1 + a3));
  double in_order = 0.0;
  for (const double x : lanes) in_order += x;
  EXPECT_NE(s.total(), in_order);  // not the running sum
}

TEST(LaneSums, VectorAndScalarTotalsAddToWhatTheSumsHeld) {
  LaneSums<3> s;
  for (std::size_t q = 0; q < 11; ++q) {
    const double x = static_cast<double>(q);
    s.add(q, Vec<3>{x, 2 * x, -x});
    s.add(q, 0.5 * x);
  }
  Vec<3> v{1.0, 1.0, 1.0};
  double e = 2.0;
  s.add_to(v, e);
  EXPECT_EQ(v[0], 1.0 + 55.0);
  EXPECT_EQ(v[1], 1.0 + 110.0);
  EXPECT_EQ(v[2], 1.0 - 55.0);
  EXPECT_EQ(e, 2.0 + 27.5);
}

}  // namespace
}  // namespace sphdisk
