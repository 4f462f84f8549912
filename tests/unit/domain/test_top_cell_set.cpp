#include "domain/top_cell_set.hpp"

#include <gtest/gtest.h>

namespace sphdisk {
namespace {

// Places follow the grid's linear order (x fastest) whatever the order and repeats of the input;
// cells outside the set, inside or outside its box, are absent; the whole cells between a cell and
// the box are counted per axis.
TEST(TopCellSet, PlacesInLinearOrderAndGapsToItsBox) {
  using C = std::array<int, 2>;
  const TopCellSet<2> set(std::vector<C>{{5, 3}, {2, 3}, {4, 1}, {2, 3}, {3, 2}});
  ASSERT_EQ(set.size(), 4u);
  EXPECT_EQ(set.place(C{4, 1}), 0u);  // row y = 1 first
  EXPECT_EQ(set.place(C{3, 2}), 1u);
  EXPECT_EQ(set.place(C{2, 3}), 2u);
  EXPECT_EQ(set.place(C{5, 3}), 3u);
  for (std::uint32_t k = 0; k < 4; ++k) EXPECT_EQ(set.place(set.coord(k)), k);
  EXPECT_EQ(set.place(C{3, 3}), TopCellSet<2>::kAbsent);  // inside the box, not in the set
  EXPECT_EQ(set.place(C{9, 9}), TopCellSet<2>::kAbsent);
  EXPECT_EQ(set.cells_apart(C{3, 2}), (C{0, 0}));
  EXPECT_EQ(set.cells_apart(C{7, 0}), (C{1, 0}));  // x: 5 is the last column; y: 0 touches 1
  EXPECT_EQ(set.cells_apart(C{0, 6}), (C{1, 2}));
  EXPECT_EQ(TopCellSet<2>().place(C{0, 0}), TopCellSet<2>::kAbsent);
}

}  // namespace
}  // namespace sphdisk
