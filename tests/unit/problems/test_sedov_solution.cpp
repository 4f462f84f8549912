// The Sedov-Taylor similarity solution (problems/sedov_solution.hpp) against the classical constants
// and its own conservation laws.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "problems/sedov_solution.hpp"

using namespace sphdisk;

// R = xi0 (E t^2 / rho0)^(1/(j+2)): Taylor's 1.033 for air (gamma = 1.4, spherical; Sedov's
// E = 0.851 rho0 R^5 / t^2), 1.152 for gamma = 5/3 (E = 0.4936 rho0 R^5 / t^2), and for a
// cylindrical blast in air E = 0.984 rho0 R^4 / t^2 (Kamm & Timmes 2007, table 1).
TEST(SedovSolution, ShockConstantsAreTheClassicalOnes) {
  EXPECT_NEAR(SedovSolution(1.4, 3).xi0(), std::pow(0.8510719, -0.2), 2e-4);
  EXPECT_NEAR(SedovSolution(5.0 / 3.0, 3).xi0(), std::pow(0.4936, -0.2), 2e-4);
  EXPECT_NEAR(SedovSolution(1.4, 2).xi0(), std::pow(0.9840418, -0.25), 2e-4);
}

TEST(SedovSolution, StrongShockJumpBehindTheFront) {
  const double gamma = 5.0 / 3.0, E = 2.0, rho0 = 3.0, t = 0.02;
  const SedovSolution s(gamma, 3);
  const double R = s.shock_radius(E, rho0, t), speed = 0.4 * R / t;
  const auto behind = s.at(R * (1 - 1e-9), E, rho0, t), ahead = s.at(R * (1 + 1e-9), E, rho0, t);
  EXPECT_NEAR(behind.rho / rho0, (gamma + 1) / (gamma - 1), 1e-6);
  EXPECT_NEAR(behind.v / speed, 2 / (gamma + 1), 1e-6);
  EXPECT_NEAR(behind.p / (rho0 * speed * speed), 2 / (gamma + 1), 1e-6);
  EXPECT_EQ(ahead.rho, rho0);
  EXPECT_EQ(ahead.v, 0.0);
  EXPECT_EQ(ahead.p, 0.0);
}

// The state integrated over the blast holds its energy E and the mass swept up, rho0 times the
// volume inside the shock (the similarity solution conserves both).
TEST(SedovSolution, ProfilesHoldTheEnergyAndTheSweptUpMass) {
  for (int j : {2, 3}) {
    for (double gamma : {1.4, 5.0 / 3.0}) {
      const double E = 1.5, rho0 = 0.7, t = 0.3;
      const SedovSolution s(gamma, j);
      const double R = s.shock_radius(E, rho0, t);
      double energy = 0, mass = 0;
      const int n = 200000;
      for (int k = 0; k < n; ++k) {
        const double r = (k + 0.5) / n * R, shell = (j == 3 ? 4 * std::numbers::pi * r * r : 2 * std::numbers::pi * r) * R / n;
        const auto x = s.at(r, E, rho0, t);
        energy += shell * (0.5 * x.rho * x.v * x.v + x.p / (gamma - 1));
        mass += shell * x.rho;
      }
      const double volume = j == 3 ? 4.0 / 3.0 * std::numbers::pi * R * R * R : std::numbers::pi * R * R;
      EXPECT_NEAR(energy / E, 1.0, 1e-3) << "j = " << j << ", gamma = " << gamma;
      EXPECT_NEAR(mass / (rho0 * volume), 1.0, 1e-3) << "j = " << j << ", gamma = " << gamma;
    }
  }
}
