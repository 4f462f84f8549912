// Particle storage: absent fields (core/particles.hpp).
#include <gtest/gtest.h>

#include <numeric>

#include "core/particles.hpp"
#include "test_helpers.hpp"

namespace sphdisk {
namespace {

// Fields set absent hold no memory, are skipped by every field visit (so sorts and copies move the
// rest alone), and come back sized to the particles with zeros; the present ones keep their values.
// A run with the leapfrog, no energy equation and the conservative force leaves out the block
// steps' state, u, du_dt, the moment correction and its shift, the artificial viscosity's limiter,
// signal speed, alpha and compression, the scatter density: 128 bytes per particle in 2D (112 with single-precision
// fields); a run that uses them all leaves out nothing.
TEST(Particles, TheRingsRunLeavesOutWhatItDoesNotUse) {
  Particles<2> p = test::random_particles<2>(1000, 3, false);
  const std::size_t all = p.bytes();
  p.set_absent_fields(unused_fields(false, false, false, false, false, false));
  EXPECT_TRUE(p.u.empty() && p.du_dt.empty() && p.u_kick.empty() && p.correction.empty() && p.v_kick.empty() &&
              p.correction_shift.empty() && p.av_limiter.empty() && p.signal_speed.empty() && p.av_alpha.empty() &&
              p.compression.empty() && p.scatter_density.empty());
  EXPECT_EQ(p.stress.size(), p.size());
  EXPECT_EQ(all - p.bytes(),
            p.size() * (8 * sizeof(double) + sizeof(std::uint64_t) + 2 * sizeof(Vec<2>) + sizeof(Mat<2, ReducedReal>)));
  EXPECT_EQ(unused_fields(true, true, true, true, true, true), 0u);
  EXPECT_EQ(unused_fields(true, false, true, false, false, false) & kForceCorrectionOnly, 0u);
  EXPECT_EQ(unused_fields(true, false, true, true, false, false) & kMixedCorrectionOnly, 0u);
  EXPECT_EQ(unused_fields(false, false, false, false, true, false) & kArtificialViscosityOnly, 0u);
  EXPECT_EQ(unused_fields(false, false, false, false, false, true) & kScatterDensityOnly, 0u);
  EXPECT_NE(unused_fields(true, true, true, true, true, false) & kScatterDensityOnly, 0u);
}

TEST(Particles, AbsentFieldsCostNothingAndComeBackAsZeros) {
  Particles<2> p = test::random_particles<2>(1000, 3, false);
  for (std::size_t i = 0; i < p.size(); ++i) p.step_ticks[i] = i + 1;
  const std::size_t all = p.bytes();
  std::size_t visited = 0, absent = 0;
  p.for_each_field([&](const FieldInfo& info, const auto&) { visited += (info.flags & kStepState) ? 1 : 0; });
  EXPECT_EQ(visited, 3u);  // step_ticks, v_kick, u_kick

  p.set_absent_fields(kStepState);
  EXPECT_EQ(p.absent_fields(), unsigned{kStepState});
  EXPECT_TRUE(p.step_ticks.empty() && p.v_kick.empty() && p.u_kick.empty());
  EXPECT_EQ(p.step_ticks.capacity(), 0u);
  EXPECT_EQ(all - p.bytes(), p.size() * (sizeof(std::uint64_t) + sizeof(Vec<2>) + sizeof(double)));
  p.for_each_field([&](const FieldInfo& info, const auto&) { absent += (info.flags & kStepState) ? 1 : 0; });
  EXPECT_EQ(absent, 0u);

  std::vector<std::uint32_t> reversed(p.size());
  std::iota(reversed.rbegin(), reversed.rend(), 0u);
  const std::vector<Vec<2>> pos = p.pos;
  p.gather(reversed);
  p.resize(p.size() + 5);
  EXPECT_EQ(p.pos[0], pos.back());
  EXPECT_TRUE(p.step_ticks.empty());
  Particles<2> copy;
  copy.set_absent_fields(p.absent_fields());
  copy.resize(3);
  copy.for_each_field_with(p, [](const FieldInfo& info, auto&, const auto&) { EXPECT_FALSE(info.flags & kStepState); });

  p.set_absent_fields(0);
  EXPECT_GE(p.bytes(), all);
  EXPECT_EQ(p.step_ticks, std::vector<std::uint64_t>(p.size(), 0));
  EXPECT_EQ(p.v_kick.size(), p.size());
  EXPECT_EQ(p.pos[0], pos.back());
}

}  // namespace
}  // namespace sphdisk
