// The artificial viscosity (physics.av_alpha): its pair term (physics/pair_terms.hpp), the Balsara
// limiter (physics/viscous_stress.hpp), and on particle sets with pressure: momentum and energy
// conserved to round-off, heating that is never negative, and signal speeds for the step limit.
#include <gtest/gtest.h>

#include <cmath>

#include "evaluate/rate_evaluator.hpp"
#include "physics/pair_terms.hpp"
#include "physics/viscosity_switch.hpp"
#include "physics/viscous_stress.hpp"
#include "test_helpers.hpp"

using namespace sphdisk;

TEST(ArtificialViscosity, PairTermActsOnApproachingPairsOnly) {
  const Vec<3> xij{{0.3, 0.4, 0.0}};  // |x_ij| = 0.5
  const Vec<3> closing{{-0.6, -0.8, 0.0}}, opening{{0.6, 0.8, 0.0}}, sliding{{0.8, -0.6, 0.0}};
  const double c_i = 0.1, c_j = 0.2, alpha = 1.0, beta = 2.0, inv_rho_i = 2.0, inv_rho_j = 4.0;
  // w = v_ij . x_ij / |x_ij| = -1: q_i / rho_i^2 = -1/2 (alpha c_i + beta) (-1) / rho_i.
  EXPECT_DOUBLE_EQ(approach_speed(xij, closing), -1.0);
  const double w = approach_speed(xij, closing);
  const PairTerms<double> q = artificial_viscosity_pair(w, c_i, c_j, inv_rho_i, inv_rho_j, 1.0, 1.0, alpha, alpha, beta);
  EXPECT_DOUBLE_EQ(q.to_i, 0.5 * (0.1 + 2.0) * 2.0);
  EXPECT_DOUBLE_EQ(q.to_j, 0.5 * (0.2 + 2.0) * 4.0);
  const PairTerms<double> limited = artificial_viscosity_pair(w, c_i, c_j, inv_rho_i, inv_rho_j, 0.25, 0.5, alpha, alpha, beta);
  EXPECT_DOUBLE_EQ(limited.to_i, 0.25 * q.to_i);
  EXPECT_DOUBLE_EQ(limited.to_j, 0.5 * q.to_j);
  // Each particle's own alpha (the switch): alpha_i = 0.5 for i, alpha_j = 0 leaves j only beta's part.
  const PairTerms<double> own = artificial_viscosity_pair(w, c_i, c_j, inv_rho_i, inv_rho_j, 1.0, 1.0, 0.5, 0.0, beta);
  EXPECT_DOUBLE_EQ(own.to_i, 0.5 * (0.5 * 0.1 + 2.0) * 2.0);
  EXPECT_DOUBLE_EQ(own.to_j, 0.5 * 2.0 * 4.0);
  for (const Vec<3>& v : {opening, sliding}) {
    EXPECT_EQ(approach_speed(xij, v), 0.0);
    const PairTerms<double> none = artificial_viscosity_pair(approach_speed(xij, v), c_i, c_j, inv_rho_i, inv_rho_j, 1.0, 1.0, alpha, alpha, beta);
    EXPECT_EQ(none.to_i, 0.0);
    EXPECT_EQ(none.to_j, 0.0);
  }
  EXPECT_DOUBLE_EQ(pair_signal_speed(w, c_i, c_j, beta), 0.2 + 2.0);
  EXPECT_DOUBLE_EQ(pair_signal_speed(approach_speed(xij, opening), c_i, c_j, beta), 0.2);
}

TEST(ArtificialViscosity, BalsaraLimiterIsOffInShearAndOnInCompression) {
  Mat<3> rotation{}, compression{}, keplerian{};
  rotation(0, 1) = -1.0, rotation(1, 0) = 1.0;
  for (int a = 0; a < 3; ++a) compression(a, a) = -1.0;
  keplerian(1, 0) = -0.75;  // the shear of a Keplerian disc at R = 1 in the local frame (d v_y / d x)
  const double c = 0.05, h = 0.03;
  EXPECT_LT(balsara_limiter(rotation, c, h), 1e-4);
  EXPECT_GT(balsara_limiter(compression, c, h), 0.999);
  EXPECT_LT(balsara_limiter(keplerian, c, h), 1e-4);
  Mat<2> converging_shear{};
  converging_shear(0, 0) = -1.0, converging_shear(1, 0) = 1.0;
  EXPECT_NEAR(balsara_limiter(converging_shear, c, h), 0.5, 1e-4);
}

namespace {

// A cloud of 3D particles converging on its centre (v = -x plus noise), isothermal, no gravity or
// physical viscosity, evaluated with the given largest alpha, each particle's own between 0.1 and it
// (as the switch leaves them).
Particles<3> converging_cloud(double alpha, PhysicsParams& phys) {
  Particles<3> p = test::random_particles<3>(3000, 7, false);
  for (auto& h : p.h) h = 0.06;  // the h solve's start
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int k = 0; k < 3; ++k) p.vel[i][k] = -(p.pos[i][k] - 0.5) + 0.1 * p.vel[i][k];
  phys = PhysicsParams{};
  phys.gm = 0.0;
  phys.eos = EquationOfState::Isothermal;
  phys.sound_speed = 0.3;
  phys.viscous_force = ViscousForce::Conservative;
  phys.evolve_energy = true;
  phys.av_alpha = alpha;
  p.set_absent_fields(unused_fields(false, true, false, false, phys.artificial_viscosity(), false));
  for (std::size_t i = 0; i < p.av_alpha.size(); ++i) p.av_alpha[i] = alpha * (0.1 + 0.9 * static_cast<double>(i % 7) / 6.0);
  PhaseTimers timers;
  RateEvaluator<3> rates(KernelType::Cubic, 0.06, phys, timers, Smoothing::Adaptive, 58.0);
  rates.evaluate(p);
  return p;
}

}  // namespace

TEST(ArtificialViscosity, ConservesMomentumAndEnergyAndOnlyHeats) {
  PhysicsParams phys;
  const Particles<3> without = converging_cloud(0.0, phys);
  const Particles<3> with = converging_cloud(1.0, phys);
  Vec<3> momentum{};
  double scale = 0, power = 0, power_scale = 0, heating = 0;
  for (std::size_t i = 0; i < with.size(); ++i) {
    momentum += with.acc[i] * with.mass[i];
    scale += with.mass[i] * std::sqrt(norm2(with.acc[i]));
    power += with.mass[i] * (dot(with.vel[i], with.acc[i]) + with.du_dt[i]);
    power_scale += with.mass[i] * (std::abs(dot(with.vel[i], with.acc[i])) + std::abs(with.du_dt[i]));
    heating += with.mass[i] * (with.du_dt[i] - without.du_dt[i]);
  }
  EXPECT_LT(std::sqrt(norm2(momentum)), 1e-13 * scale);
  EXPECT_LT(std::abs(power), 1e-13 * power_scale);  // kinetic + internal energy: the AV's work is its heating
  EXPECT_GT(heating, 0.0);
  // It brakes the convergence: the kinetic energy falls faster than with pressure alone.
  double braking = 0;
  for (std::size_t i = 0; i < with.size(); ++i) braking += with.mass[i] * dot(with.vel[i], with.acc[i] - without.acc[i]);
  EXPECT_LT(braking, 0.0);
  // Every particle's signal speed is at least its sound speed, and the converging pairs raise it.
  double largest = 0;
  for (std::size_t i = 0; i < with.size(); ++i) {
    EXPECT_GE(with.signal_speed[i], 0.3);
    largest = std::max(largest, with.signal_speed[i]);
    EXPECT_GE(with.av_limiter[i], 0.0);
    EXPECT_LE(with.av_limiter[i], 1.0);
  }
  EXPECT_GT(largest, 0.3 + 2.0 * 0.05);
  EXPECT_TRUE(without.signal_speed.empty());  // absent without the artificial viscosity
}

// The Morris-Monaghan switch (physics/viscosity_switch.hpp): decay to alpha_min on the time scale
// h / (0.1 c) without compression, a rise to alpha_max where it dominates, exact over any step.
TEST(ArtificialViscosity, SwitchDecaysAndRisesWithinItsBounds) {
  PhysicsParams phys;
  phys.av_alpha = 1.0;
  phys.av_alpha_min = 0.1;
  const double h = 0.02, c = 0.5, tau = h / (kViscositySwitchDecay * c);
  // No compression: alpha - alpha_min falls by e over tau.
  EXPECT_NEAR(switched_alpha(1.0, 0.0, h, c, tau, phys) - 0.1, 0.9 * std::exp(-1.0), 1e-14);
  // Two half steps are one step (constant coefficients, integrated exactly).
  const double S = 3.0 / tau;
  EXPECT_NEAR(switched_alpha(switched_alpha(0.2, S, h, c, 0.5 * tau, phys), S, h, c, 0.5 * tau, phys),
              switched_alpha(0.2, S, h, c, tau, phys), 1e-14);
  // A compression S settles at (alpha_min / tau + S alpha_max) / (1 / tau + S): 0.775 at S tau = 3.
  EXPECT_NEAR(switched_alpha(0.1, S, h, c, 1e3 * tau, phys), (0.1 + 3.0) / 4.0, 1e-12);
  // A shock (S tau = 1e4) lifts it to nearly alpha_max within a few of its own rise times.
  EXPECT_GT(switched_alpha(0.1, 1e4 / tau, h, c, 5e-4 * tau, phys), 0.99);
  // Within [alpha_min, alpha_max] for any step and start within them.
  for (double dt : {0.0, 1e-6, 1.0, 1e6})
    for (double start : {0.1, 0.5, 1.0}) {
      const double a = switched_alpha(start, S, h, c, dt * tau, phys);
      EXPECT_GE(a, 0.1 - 1e-15);
      EXPECT_LE(a, 1.0 + 1e-15);
    }
}
