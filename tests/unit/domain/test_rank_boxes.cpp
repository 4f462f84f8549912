#include "domain/rank_boxes.hpp"

#include <gtest/gtest.h>

namespace sphdisk {
namespace {

RankBoxes<2> rank_with(std::array<double, 2> lo, std::array<double, 2> hi, double reach) {
  RankBoxes<2> r;
  r.particles.include(lo, hi, reach);
  return r;
}

// Four ranks in a row of unit squares along x, rank 0 reading in its right half with need 0.3:
// only rank 1 (gap 0) gets the list; rank 2 (gap 1.0) does once its particles' reach passes the
// gap, and never rank 3 (gap 2.0); ranks without readers send nothing; the boxes survive the
// values they are gathered as.
TEST(RankBoxes, ListsGoOnlyToRanksWithinReach) {
  std::vector<RankBoxes<2>> all;
  for (int k = 0; k < 4; ++k) all.push_back(rank_with({double(k), 0.0}, {k + 1.0, 1.0}, 0.1));
  all[0].readers.include({0.5, 0.0}, {1.0, 1.0}, 0.3);
  EXPECT_EQ(list_recipients(all, 0), (std::vector<std::size_t>{1}));
  EXPECT_TRUE(list_recipients(all, 1).empty());
  all[2].particles.include({2.0, 0.0}, {3.0, 1.0}, 1.01);
  EXPECT_EQ(list_recipients(all, 0), (std::vector<std::size_t>{1, 2}));
  all[0].readers.include({0.5, 0.0}, {1.0, 1.0}, 2.01);
  EXPECT_EQ(list_recipients(all, 0), (std::vector<std::size_t>{1, 2, 3}));
  std::vector<double> gathered;
  for (const auto& r : all)
    for (const double v : r.values()) gathered.push_back(v);
  const auto back = RankBoxes<2>::of_values(gathered);
  ASSERT_EQ(back.size(), all.size());
  for (std::size_t me = 0; me < all.size(); ++me) EXPECT_EQ(list_recipients(back, me), list_recipients(all, me));
}

// A diagonal gap counts in both directions: boxes 0.3 apart in x and 0.4 in y are 0.5 apart.
TEST(RankBoxes, GapIsEuclideanBetweenBoxes) {
  RankBox<2> a, b;
  a.include({0.0, 0.0}, {1.0, 1.0}, 0.0);
  b.include({1.3, 1.4}, {2.0, 2.0}, 0.0);
  EXPECT_DOUBLE_EQ(a.gap2(b), 0.25);
  EXPECT_DOUBLE_EQ(b.gap2(a), 0.25);
  EXPECT_TRUE(RankBox<2>().empty());
}

}  // namespace
}  // namespace sphdisk
