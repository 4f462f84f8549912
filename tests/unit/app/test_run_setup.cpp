// The set-up's sound speed (app/run_setup.hpp): physics.aspect_ratio gives it at r0, and
// physics.alpha_max raises it where the constant viscosity would exceed alpha_max c_s H there
// (H = c_s / Omega), in code units (r0 = G M = 1, so Omega(r0) = v_Kepler(r0) = 1).
#include <gtest/gtest.h>

#include <cmath>

#include "app/run_setup.hpp"
#include "core/config.hpp"

using namespace sphdisk;

TEST(RunSetup, SoundSpeedRaisedToTheLargestAlpha) {
  const std::vector<std::string> cold = {"physics.eos=\"locally_isothermal\"", "physics.sound_speed_index=0.25"};
  auto with = [&](std::vector<std::string> extra) {
    extra.insert(extra.end(), cold.begin(), cold.end());
    return make_setup(parse_config("", "test.toml", extra));
  };
  // Alone: nu = alpha c_s H exactly.
  const sphdisk::Setup by_alpha = with({"physics.alpha_max=2.0"});
  const double nu = by_alpha.phys.nu, c = by_alpha.phys.sound_speed;
  ASSERT_GT(nu, 0.0);
  EXPECT_NEAR(nu, 2.0 * c * (c / 1.0), 1e-15 * nu);
  EXPECT_NEAR(c, 0.00489, 1e-5);  // the paper's viscosity: H/R = 0.0049 at r0
  // With H/R 0.005 given, which keeps alpha below 2 at the paper's viscosity: unchanged.
  EXPECT_EQ(with({"physics.alpha_max=2.0", "physics.aspect_ratio=0.005"}).phys.sound_speed, 0.005);
  EXPECT_EQ(with({"physics.aspect_ratio=0.005"}).phys.sound_speed, 0.005);
  // Four times the viscosity: raised to twice the alpha-bound sound speed above.
  const sphdisk::Setup x4 = with({"physics.alpha_max=2.0", "physics.aspect_ratio=0.005", "physics.viscosity=1.2e-7"});
  EXPECT_NEAR(x4.phys.sound_speed, 2.0 * c, 1e-12);
  EXPECT_THROW(with({"physics.alpha_max=2.0", "physics.viscosity=0"}), UserError);
}
