// Scratch buffers (core/overwrite_vector.hpp, core/large_allocations.hpp): large ones on huge-page
// aligned mappings, small ones from operator new, both keeping their entries through growth.
#include <gtest/gtest.h>

#include <cstdint>

#include "core/large_allocations.hpp"
#include "core/overwrite_vector.hpp"
#include "core/vec.hpp"

namespace sphdisk {
namespace {

TEST(ScratchBuffers, LargeOnesLieOnHugePageBoundariesAndKeepTheirEntries) {
  OverwriteVector<double> v;
  for (std::size_t n : {std::size_t{1000}, kHugePageScratch / sizeof(double) - 1, kHugePageScratch / sizeof(double),
                        3 * kHugePageScratch / sizeof(double) + 5}) {
    const std::size_t old = v.size();
    v.resize(n);
    for (std::size_t k = old; k < n; ++k) v[k] = static_cast<double>(k);
    for (std::size_t k = 0; k < n; ++k) ASSERT_EQ(v[k], static_cast<double>(k)) << "n " << n;
    const bool huge = on_huge_pages(v.capacity() * sizeof(double));
#if defined(__linux__)
    EXPECT_EQ(huge, v.capacity() * sizeof(double) >= kHugePageScratch);
#endif
    if (huge) EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % kHugePage, 0u) << "n " << n;
  }
  v = OverwriteVector<double>();  // (freed: the mapping's whole huge pages)
  UnsetVector<Mat<3>> sums(kHugePageScratch / sizeof(Mat<3>) + 1);
  sums.back().c[8] = 2.5;
  EXPECT_EQ(sums.back().c[8], 2.5);
  EXPECT_EQ(whole_huge_pages(1), kHugePage);
  EXPECT_EQ(whole_huge_pages(kHugePage), kHugePage);
  EXPECT_EQ(whole_huge_pages(kHugePage + 1), 2 * kHugePage);
}

}  // namespace
}  // namespace sphdisk
