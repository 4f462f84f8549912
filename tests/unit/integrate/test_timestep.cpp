// Timestep criteria (integrate/timestep.hpp): the Courant limit follows the local sound speed of a
// locally isothermal gas, c_s(R) = c_s0 R^-q, so the inner particles take the shorter steps.
#include <gtest/gtest.h>

#include <cmath>

#include "integrate/timestep.hpp"

using namespace sphdisk;

TEST(Timestep, CourantLimitFollowsTheLocalSoundSpeed) {
  Particles<2> p;
  p.resize(2);
  p.pos[0] = Vec<2>{{0.5, 0.0}};
  p.pos[1] = Vec<2>{{0.0, 2.0}};
  for (std::size_t i = 0; i < 2; ++i) {
    p.h[i] = 0.01;
    p.mass[i] = 1.0;
  }
  PhysicsParams phys;
  phys.gm = 1e-12;  // the orbital and force limits far away
  phys.eos = EquationOfState::LocallyIsothermal;
  phys.sound_speed = 0.05;
  phys.sound_speed_index = 0.25;
  TimestepFactors f;
  f.orbital = 1e6;
  for (std::size_t i = 0; i < 2; ++i) {
    const double R = norm(p.pos[i]);
    EXPECT_DOUBLE_EQ(particle_timestep(p, i, phys, f), f.courant * 0.01 / (0.05 * std::pow(R, -0.25)));
  }
  EXPECT_DOUBLE_EQ(largest_sound_speed(p, phys), 0.05 * std::pow(0.5, -0.25));
  phys.eos = EquationOfState::Isothermal;  // one c_s everywhere
  EXPECT_DOUBLE_EQ(particle_timestep(p, 0, phys, f), particle_timestep(p, 1, phys, f));
}

// With an alpha viscosity the viscous limit takes each particle's nu = alpha c_s^2 / Omega.
TEST(Timestep, ViscousLimitFollowsTheLocalAlphaViscosity) {
  Particles<2> p;
  p.resize(1);
  p.pos[0] = Vec<2>{{3.0, 0.0}};
  p.h[0] = 0.02;
  p.mass[0] = 1.0;
  PhysicsParams phys;
  phys.gm = 1.0;
  phys.eos = EquationOfState::Isothermal;
  phys.sound_speed = 0.05;
  phys.alpha_ss = 0.1;
  TimestepFactors f;
  f.orbital = f.courant = 1e6;  // only the viscous limit binds
  const double nu = 0.1 * 0.05 * 0.05 * std::pow(3.0, 1.5);
  EXPECT_DOUBLE_EQ(particle_timestep(p, 0, phys, f), f.viscous * 0.02 * 0.02 / nu);
  EXPECT_DOUBLE_EQ(largest_viscosity(p, phys), nu);
}
