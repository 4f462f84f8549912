// SPH operators against analytic answers (P98 eqs. 6-8): exact gradients of linear velocity
// fields on a lattice, zero viscous force for translation and rigid rotation, the divergence of the
// stress for quadratic fields, and exact conservation of momentum and energy.
#include <numbers>
#include <gtest/gtest.h>

#include "evaluate/rate_evaluator.hpp"
#include "physics/viscous_stress.hpp"
#include "test_helpers.hpp"

using namespace sphdisk;

namespace {

constexpr int kN = 48;
constexpr double kDx = 1.0 / kN;
constexpr double kHalf = 0.5 * kN * kDx;

struct Evaluated {
  Particles<2> p;
  std::vector<std::size_t> inner;  // particles whose neighbours' neighbours are all inside
};

// Lattice with velocity field v(x), rates evaluated with smoothing length h = eta dx.
template <class F>
Evaluated evaluate_lattice(F&& velocity, PhysicsParams phys, double eta = 1.3, KernelType kernel = KernelType::Cubic) {
  Evaluated e{test::square_lattice(kN, kDx), {}};
  for (std::size_t i = 0; i < e.p.size(); ++i) e.p.vel[i] = velocity(e.p.pos[i]);
  phys.gm = 0.0;  // no gravity: these tests check the hydrodynamic terms alone
  PhaseTimers timers;
  RateEvaluator<2> rates(kernel, eta * kDx, phys, timers);
  rates.evaluate(e.p);
  // 3 supports: the stress of every neighbour then uses densities untouched by the lattice edge.
  e.inner = test::interior(e.p, kHalf, 3.0 * 2.0 * eta * kDx + 1e-9);
  return e;
}

PhysicsParams viscous(double nu, double nu_bulk = 0.0) {
  PhysicsParams p;
  p.nu = nu;
  p.nu_bulk = nu_bulk;
  return p;
}

}  // namespace

// Eq. 8 applied to v = A x + b gives V = A M with the lattice moment
// M = sum_j (m_j / rho_j) (x_j - x_i) (x_i - x_j)^T W'/r, which is c I on a square lattice (by
// symmetry) with c -> 1 as h/dx grows. So V must equal c A up to the rounding of the stored
// single-precision kernel factors (2^-24 relative each; measured 2e-8), and A itself to the
// lattice-sum accuracy (3e-5 at h = 2.2 dx for the cubic spline; ~1% at h = 1.2-1.8 dx).
void check_linear_gradient(double eta, double tolerance_vs_exact) {
  const double A[2][2] = {{0.3, -1.1}, {0.7, 0.2}};
  auto e = evaluate_lattice([&](const Vec<2>& x) {
    return Vec<2>{{A[0][0] * x[0] + A[0][1] * x[1] + 5.0, A[1][0] * x[0] + A[1][1] * x[1] - 2.0}};
  }, viscous(1.0), eta);
  PhaseTimers timers;
  RateEvaluator<2> rates(KernelType::Cubic, eta * kDx, viscous(1.0), timers);
  rates.evaluate(e.p);
  const KernelAt<CubicSpline, 2> kern(eta * kDx);
  ASSERT_GT(e.inner.size(), 100u);
  double worst_vs_cA = 0, worst_vs_A = 0;
  for (std::size_t i : e.inner) {
    double c = 0;  // M_xx by a direct loop over all particles (independent of the neighbour lists)
    for (std::size_t j = 0; j < e.p.size(); ++j) {
      const Vec<2> dx = e.p.pos[i] - e.p.pos[j];
      c -= e.p.mass[j] / e.p.rho[j] * dx[0] * dx[0] * kern.dW_over_r(norm(dx));
    }
    const Mat<2> V = rates.gradient_sums()[i].V;
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) {
        worst_vs_cA = std::max(worst_vs_cA, std::abs(V(a, b) - c * A[a][b]));
        worst_vs_A = std::max(worst_vs_A, std::abs(V(a, b) - A[a][b]));
      }
  }
  EXPECT_LT(worst_vs_cA, 1e-7);
  EXPECT_LT(worst_vs_A, tolerance_vs_exact);
}

TEST(VelocityGradient, ExactForLinearFieldsOnALattice) {
  check_linear_gradient(2.2, 1e-4);
  check_linear_gradient(1.3, 2e-2);
}

// On a disordered set the plain sum (eq. 8) is off by the moment matrix M (self term of the density,
// missing support at the edge); V M^-1 recovers A for every particle, edge ones included, up to the
// single-precision pair factors.
TEST(VelocityGradient, CorrectedExactForLinearFieldsOnRandomSets) {
  const double A[2][2] = {{0.3, -1.1}, {0.7, 0.2}};
  auto p = test::random_particles<2>(4000, 3, false);
  for (auto& x : p.pos) x += Vec<2>{{2.0, 2.0}};
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec<2> x = p.pos[i];
    p.vel[i] = Vec<2>{{A[0][0] * x[0] + A[0][1] * x[1] + 5.0, A[1][0] * x[0] + A[1][1] * x[1] - 2.0}};
  }
  PhysicsParams phys = viscous(1.0);
  phys.gm = 0.0;
  PhaseTimers timers;
  RateEvaluator<2> rates(KernelType::Cubic, 0.06, phys, timers);  // ~50 neighbours
  rates.evaluate(p);
  double worst_corrected = 0, worst_plain = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto g = rates.gradient_sums()[i];
    const Mat<2> G = corrected_gradient(g);
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) {
        worst_corrected = std::max(worst_corrected, std::abs(G(a, b) - A[a][b]));
        worst_plain = std::max(worst_plain, std::abs(g.V(a, b) - A[a][b]));
      }
  }
  EXPECT_LT(worst_corrected, 1e-5);
  EXPECT_GT(worst_plain, 0.1);  // what the correction is for
}

// The mixed correction (physics_params.hpp, GradientCorrection::Mixed) on the same kind of set, with
// adaptive h (each pair's W and grad W averaged over both kernels): the gradient is A for every
// particle (any shift of the kernel gradient keeps the sums linear-exact), and a particle's own
// velocity does not enter its gradient: a velocity kick at one interior particle leaves that
// particle's gradient unchanged (its weights sum to zero), where the linear correction changes it
// by C sum_k V_k grad W_ik, the zeroth-moment error of the disordered set. The shift is full there
// (|d| << 1, pair_terms.hpp), so the weights' sum is zero to round-off.
TEST(VelocityGradient, MixedCorrectionExactForLinearFieldsAndBlindToTheOwnVelocity) {
  const double A[2][2] = {{0.3, -1.1}, {0.7, 0.2}};
  Particles<2> p = test::random_particles<2>(4000, 3, false);
  for (auto& x : p.pos) x += Vec<2>{{2.0, 2.0}};
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec<2> x = p.pos[i];
    p.vel[i] = Vec<2>{{A[0][0] * x[0] + A[0][1] * x[1] + 5.0, A[1][0] * x[0] + A[1][1] * x[1] - 2.0}};
    p.h[i] = 0.06;  // the smoothing-length solve's start
  }
  const auto stresses = [&](GradientCorrection correction, std::size_t kicked) {  // kicked = n: none
    Particles<2> q = p;
    if (kicked < q.size()) q.vel[kicked] += Vec<2>{{1.0, -0.5}};
    PhysicsParams phys = viscous(1.0);
    phys.gm = 0.0;
    phys.gradient_correction = correction;
    PhaseTimers timers;
    RateEvaluator<2> rates(KernelType::Cubic, 0.06, phys, timers, Smoothing::Adaptive, 50);
    rates.evaluate(q);
    EXPECT_EQ(q.id, p.id);  // (the evaluation keeps the particles' order)
    std::vector<Mat<2>> S(q.size());
    for (std::size_t i = 0; i < q.size(); ++i) S[i] = as_double(q.stress[i]);
    return S;
  };
  // The kicked particle: the one nearest the middle.
  std::size_t middle = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (norm2(p.pos[i] - Vec<2>{{2.5, 2.5}}) < norm2(p.pos[middle] - Vec<2>{{2.5, 2.5}})) middle = i;
  const double S_exact[2][2] = {{2 * A[0][0] - 2.0 / 3.0 * 0.5, A[0][1] + A[1][0]}, {A[0][1] + A[1][0], 2 * A[1][1] - 2.0 / 3.0 * 0.5}};
  double worst_linear_field = 0;
  for (const Mat<2>& S : stresses(GradientCorrection::Mixed, p.size()))
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) worst_linear_field = std::max(worst_linear_field, std::abs(S(a, b) - S_exact[a][b]));
  EXPECT_LT(worst_linear_field, 1e-5);
  const auto own_change = [&](GradientCorrection correction) {
    const Mat<2> kicked = stresses(correction, middle)[middle], unkicked = stresses(correction, p.size())[middle];
    double change = 0;
    for (std::size_t c = 0; c < 4; ++c) change = std::max(change, std::abs(kicked.c[c] - unkicked.c[c]));
    return change;
  };
  EXPECT_LT(own_change(GradientCorrection::Mixed), 1e-9);
  EXPECT_GT(own_change(GradientCorrection::Linear), 0.1);
}

// With the corrected gradient a rigid rotation has zero shear on any particle set.
TEST(ViscousForce, ZeroStressForRigidRotationOnRandomSets) {
  const double omega = 2.5, nu = 0.1;
  auto p = test::random_particles<2>(4000, 4, true);
  for (std::size_t i = 0; i < p.size(); ++i) p.vel[i] = Vec<2>{{-omega * p.pos[i][1], omega * p.pos[i][0]}};
  PhysicsParams phys = viscous(nu, 0.05);
  phys.gm = 0.0;
  PhaseTimers timers;
  RateEvaluator<2> rates(KernelType::Cubic, 0.03, phys, timers);
  rates.evaluate(p);
  double worst = 0;
  for (const auto& S : p.stress)
    for (double s : S.c) worst = std::max(worst, std::abs(s));
  EXPECT_LT(worst, 1e-6 * nu * omega);
}

TEST(ViscousForce, ZeroForUniformTranslation) {
  auto e = evaluate_lattice([](const Vec<2>&) { return Vec<2>{{3.0, -4.0}}; }, viscous(0.1, 0.05));
  for (std::size_t i = 0; i < e.p.size(); ++i) {  // every particle: dv = 0 exactly
    EXPECT_EQ(e.p.acc[i][0], 0.0);
    EXPECT_EQ(e.p.acc[i][1], 0.0);
  }
}

TEST(ViscousForce, ZeroForRigidRotation) {
  const double omega = 2.5;
  auto e = evaluate_lattice([&](const Vec<2>& x) { return Vec<2>{{-omega * x[1], omega * x[0]}}; }, viscous(0.1, 0.05));
  // Scale of a non-zero viscous acceleration for comparison: nu * omega / dx.
  const double scale = 0.1 * omega / kDx;
  for (std::size_t i : e.inner) {
    EXPECT_LT(std::abs(e.p.acc[i][0]), 1e-11 * scale);
    EXPECT_LT(std::abs(e.p.acc[i][1]), 1e-11 * scale);
  }
}

// Locally isothermal gas at rest with uniform density (P = c_s0^2 R^-2q rho, docs/physics.md sec. 4)
// on a lattice centred at (2, 0): the pressure force is -grad P / rho = 2 q c_s0^2 R^(-2q-1) R^,
// outward. Isothermal gas (q = 0) feels none.
TEST(PressureForce, LocallyIsothermalMatchesTheAnalyticGradient) {
  for (const double q : {0.0, 0.5, 1.0}) {
    Particles<2> p = test::square_lattice(kN, kDx);
    const double eta = 2.2;
    const std::vector<std::size_t> inner = test::interior(p, kHalf, 2.0 * 2.0 * eta * kDx + 1e-9);
    ASSERT_GT(inner.size(), 100u);
    for (auto& x : p.pos) x[0] += 2.0;
    PhysicsParams phys;
    phys.gm = 0.0;
    phys.eos = EquationOfState::LocallyIsothermal;
    phys.sound_speed = 0.1;
    phys.sound_speed_index = q;
    PhaseTimers timers;
    RateEvaluator<2> rates(KernelType::Cubic, eta * kDx, phys, timers);
    rates.evaluate(p);
    double worst = 0;
    const double scale = 2.0 * 0.5 * 0.01 * std::pow(2.5, -2.0);  // the q = 0.5 force's size
    for (std::size_t i : inner) {
      const Vec<2> x = p.pos[i];
      const double R = norm(x);
      const double a = 2.0 * q * 0.01 * std::pow(R, -2.0 * q - 1.0);
      const Vec<2> expected = x * (a / R);
      worst = std::max(worst, norm(p.acc[i] - expected) / scale);
      EXPECT_DOUBLE_EQ(sound_speed_at(phys, p.pos[i]), 0.1 * std::pow(R, -q));
    }
    std::printf("q = %.1f: largest deviation %.2e of the q = 0.5 force\n", q, worst);
    EXPECT_LT(worst, 0.01) << "q = " << q;
  }
}

// Alpha viscosity (physics.alpha_ss): each particle's stress takes nu = alpha c_s(R)^2 / Omega(R),
// with the locally isothermal c_s(R) = c_s0 R^-q and Omega = (G M / R^3)^(1/2): for a linear
// velocity field, whose corrected gradient is exact, S_i = nu(R_i) (A + A^T - (2/3) tr A I).
// With physics.bulk_viscosity_ratio the bulk viscosity follows each particle's own shear viscosity.
TEST(VelocityGradient, AlphaViscositySetsEachParticlesStressAndBulkShare) {
  const double A[2][2] = {{0.1, 0.3}, {-0.2, 0.05}};
  const double alpha = 0.01, c0 = 0.05, q = 0.25;
  for (const double bulk_ratio : {0.0, 1.5}) {
    Particles<2> p = test::square_lattice(kN, kDx);
    const std::vector<std::size_t> inner = test::interior(p, kHalf, 2.0 * 1.3 * kDx + 1e-9);
    for (std::size_t i = 0; i < p.size(); ++i) {
      p.pos[i][0] += 2.0;
      const Vec<2>& x = p.pos[i];
      p.vel[i] = Vec<2>{{A[0][0] * x[0] + A[0][1] * x[1], A[1][0] * x[0] + A[1][1] * x[1]}};
    }
    PhysicsParams phys;
    phys.gm = 1.0;  // Omega's; the point mass's gravity is left out of the rates below
    phys.eos = EquationOfState::LocallyIsothermal;
    phys.sound_speed = c0;
    phys.sound_speed_index = q;
    phys.alpha_ss = alpha;
    phys.bulk_ratio = bulk_ratio;
    PhaseTimers timers;
    RateEvaluator<2> rates(KernelType::Cubic, 1.3 * kDx, phys, timers);
    rates.include_gravity(false);
    rates.evaluate(p);
    double worst = 0;
    for (std::size_t i : inner) {
      const double R = norm(p.pos[i]);
      const double nu = alpha * c0 * c0 * std::pow(R, -2.0 * q) * std::pow(R, 1.5);
      EXPECT_NEAR(shear_viscosity_at(phys, p.pos[i]), nu, 1e-13 * nu);
      const double trace = A[0][0] + A[1][1];
      for (int a = 0; a < 2; ++a)
        for (int c = 0; c < 2; ++c) {
          const double expected = nu * (A[a][c] + A[c][a] + (a == c ? (bulk_ratio - 2.0 / 3.0) * trace : 0.0));
          worst = std::max(worst, std::abs(static_cast<double>(p.stress[i](a, c)) - expected) / (nu * 0.5));
        }
    }
    EXPECT_LT(worst, kSinglePrecisionFields ? 1e-6 : 1e-9) << "bulk_ratio " << bulk_ratio;  // (float stress in the single preset)
  }
}

// v = (a x^2, b x y): (1/rho) div t = (nu (2a + (2a+b)/3) + nu_b (2a+b), 0)   [eq. 1 with eq. 2]
TEST(ViscousForce, MatchesAnalyticDivergenceOfStressForQuadraticField) {
  const double a = 0.8, b = -0.5, nu = 0.01, nu_b = 0.004;
  // h = 2.2 dx, where lattice sums are accurate (see ExactForLinearFieldsOnALattice): at smaller h
  // the error is the square of the ~1% lattice-moment error, one factor per derivative.
  auto e = evaluate_lattice([&](const Vec<2>& x) { return Vec<2>{{a * x[0] * x[0], b * x[0] * x[1]}}; }, viscous(nu, nu_b), 2.2);
  const double ax = nu * (2 * a + (2 * a + b) / 3.0) + nu_b * (2 * a + b);
  double worst = 0;
  for (std::size_t i : e.inner) {
    worst = std::max(worst, std::abs(e.p.acc[i][0] - ax) / std::abs(ax));
    worst = std::max(worst, std::abs(e.p.acc[i][1]) / std::abs(ax));
  }
  EXPECT_LT(worst, 1e-3);
}

// v_x = a y^2 (shear flow, div v = 0): (1/rho) div t = (2 a nu, 0), for every kernel.
TEST(ViscousForce, MatchesAnalyticForPoiseuilleProfileWithEveryKernel) {
  const double a = 1.5, nu = 0.02;
  for (KernelType k : {KernelType::Cubic, KernelType::WendlandC2, KernelType::WendlandC4}) {
    auto e = evaluate_lattice([&](const Vec<2>& x) { return Vec<2>{{a * x[1] * x[1], 0.0}}; }, viscous(nu), 1.6, k);
    double worst = 0;
    for (std::size_t i : e.inner) worst = std::max(worst, std::abs(e.p.acc[i][0] - 2 * a * nu) / (2 * a * nu));
    EXPECT_LT(worst, 0.02) << "kernel " << static_cast<int>(k);
  }
}

// On a disordered set with arbitrary velocities, the conservative form of eq. 6: sum m a = 0 and
// d(E_kin + U)/dt = 0 to round-off (with the corrected gradient, the default). Angular momentum is
// not exact in this form: the pair force (S_i/rho_j + S_j/rho_i) . grad W is not central.
TEST(Conservation, MomentumAndEnergyExactOnRandomSets) {
  for (bool force_correction : {false, true}) {
    auto p = test::random_particles<2>(3000, 11, true);
    for (auto& x : p.pos) x += Vec<2>{{2.0, 2.0}};  // away from the origin (gravity is off anyway)
    PhysicsParams phys = viscous(0.01, 0.003);
    phys.gm = 0.0;
    phys.eos = EquationOfState::Isothermal;
    phys.sound_speed = 0.3;
    phys.evolve_energy = true;
    phys = test::with_form(phys, force_correction ? test::Form::ForceCorrected : test::Form::Conservative);
    PhaseTimers timers;
    RateEvaluator<2> rates(KernelType::WendlandC2, 0.02, phys, timers);
    rates.evaluate(p);
    test::expect_momentum_and_energy_conserved(p, force_correction ? "force correction on" : "force correction off");
  }
}

// Without an energy equation the particles hold no u and du_dt, and where no force reads it no
// moment correction (core/particles.hpp, unused_fields): the rates of such lean particles must be
// those of particles holding every field, bit for bit, with and without pressure, in each form of
// eq. 6, with stored pairs and with pairs searched anew (whose gradient and force loops are then
// joined even with the force correction: no heating loop lies between them).
TEST(Conservation, FieldsARunDoesNotUseChangeNoRate) {
  for (test::Form form : {test::Form::Conservative, test::Form::ForceCorrected, test::Form::Consistent, test::Form::ConsistentMixed})
    for (bool pressure : {false, true})
      for (PairStorage storage : {PairStorage::Stored, PairStorage::Rescan}) {
        Particles<2> full = test::random_particles<2>(2000, 5, true);
        for (auto& x : full.pos) x += Vec<2>{{2.0, 2.0}};
        Particles<2> lean = full;
        PhysicsParams phys = viscous(0.01, 0.003);
        phys.gm = 0.0;
        phys.eos = pressure ? EquationOfState::Isothermal : EquationOfState::None;
        phys.sound_speed = 0.3;
        phys = test::with_form(phys, form);
        const bool force_correction = phys.keeps_correction();
        lean.set_absent_fields(unused_fields(false, false, force_correction, phys.keeps_correction_shift(), false, false));
        for (Particles<2>* p : {&full, &lean}) {
          PhaseTimers timers;
          RateEvaluator<2> rates(KernelType::WendlandC2, 0.02, phys, timers);
          rates.set_pair_storage(storage);
          rates.evaluate(*p);
        }
        SCOPED_TRACE(std::string(test::form_name(form)) + ", pressure " +
                     (pressure ? "on" : "off") + (storage == PairStorage::Rescan ? ", rescan" : ", stored"));
        EXPECT_TRUE(lean.u.empty() && lean.du_dt.empty());
        EXPECT_EQ(lean.correction.empty(), !force_correction);
        EXPECT_EQ(lean.correction_shift.empty(), !phys.keeps_correction_shift());
        ASSERT_EQ(lean.size(), full.size());
        for (std::size_t i = 0; i < full.size(); ++i) {
          ASSERT_EQ(lean.rho[i], full.rho[i]) << i;
          ASSERT_EQ(lean.acc[i], full.acc[i]) << i;
          for (std::size_t c = 0; c < 4; ++c) ASSERT_EQ(lean.stress[i].c[c], full.stress[i].c[c]) << i;
        }
      }
}

// The moment-corrected pair gradient (sph.force_correction) makes eq. 6's divergence exact to first
// order where the plain kernel gradient carries the lattice moment: at h = 1.3 dx the shear-flow
// force v_x = a y^2 -> (2 a nu, 0) is ~1-2% off with the plain gradient, and must come out closer.
TEST(ViscousForce, ForceCorrectionReducesTheLatticeMomentError) {
  const double a = 1.5, nu = 0.02;
  double worst[3] = {0, 0, 0};
  for (test::Form form : {test::Form::Conservative, test::Form::ForceCorrected, test::Form::Consistent}) {
    const PhysicsParams phys = test::with_form(viscous(nu), form);
    auto e = evaluate_lattice([&](const Vec<2>& x) { return Vec<2>{{a * x[1] * x[1], 0.0}}; }, phys, 1.3);
    const auto k = static_cast<std::size_t>(form);
    for (std::size_t i : e.inner) worst[k] = std::max(worst[k], std::abs(e.p.acc[i][0] - 2 * a * nu) / (2 * a * nu));
  }
  EXPECT_GT(worst[0], 5e-3);  // the error the correction is for
  EXPECT_LT(worst[1], 0.2 * worst[0]);
  EXPECT_LT(worst[2], 0.2 * worst[0]);  // the consistent form is first-order exact too
}

// The consistent form of eq. 6's divergence (physics_params.hpp) on hand-placed, disordered
// neighbours with unequal masses: for a linear stress S(x) = S0 + B x and a linear log-density
// ln rho(x) = l0 + k . x, particle i's sum must equal (1/rho) div(rho S) = div S + S . k at x_i to
// round-off, whatever the particle arrangement (the conservative form is off by S . sum_j m_j
// (1/rho_i + 1/rho_j) grad W, which only ordered particles make small). Each partner's term of the
// pair, added to acc[j], must be the same formula seen from j (checked against j's own list {i}).
TEST(ViscousForce, ConsistentFormIsExactForLinearStressAndLogDensityOnAnyParticles) {
  const double h = 0.1;
  const KernelAt<CubicSpline, 2> kern(h);
  const Vec<2> k{{1.7, -0.6}};
  const Mat<2> S0{{0.4, -1.3, -1.3, 0.2}};
  const double B[2][2][2] = {{{0.5, -2.0}, {1.0, 0.3}}, {{-0.7, 0.9}, {0.2, 1.4}}};  // dS_ab/dx_c = B[a][b][c]
  auto stress_at = [&](const Vec<2>& x) {
    Mat<2> S = S0;
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) S(a, b) += B[a][b][0] * x[0] + B[a][b][1] * x[1];
    return S;
  };
  for (bool linear_stress : {false, true}) {
    std::mt19937_64 g(77);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const std::size_t n = 70;  // particle 0 and its partners, all within the support 2h
    std::vector<Vec<2>> pos(n), vel(n), acc(n);
    std::vector<Mat<2, ReducedReal>> stress(n), correction(n);
    std::vector<double> mass(n), inv_rho(n), log_rho(n), volume(n);
    for (std::size_t j = 0; j < n; ++j) {
      do pos[j] = j == 0 ? Vec<2>{{0.3, -0.2}} : Vec<2>{{0.3 + 2 * h * u(g), -0.2 + 2 * h * u(g)}};
      while (j > 0 && norm(pos[j] - pos[0]) > 1.9 * h);
      if (j > 0 && j % 3 == 0) pos[j] = pos[0] + (pos[j] - pos[0]) * 0.3;  // a clump on one side
      mass[j] = 1.0 + 0.5 * u(g);
      log_rho[j] = 0.8 + dot(k, pos[j]);
      inv_rho[j] = std::exp(-log_rho[j]);
      volume[j] = mass[j] * inv_rho[j];
      store(stress[j], linear_stress ? stress_at(pos[j]) : S0);
      correction[j] = {};
    }
    // Particle 0's moment matrix M = -sum_j V_j F dx (x) dx and its correction C = M^-1.
    std::vector<std::uint32_t> js;
    std::vector<float> F;
    Mat<2> M;
    for (std::uint32_t j = 1; j < n; ++j) {
      js.push_back(j);
      F.push_back(static_cast<float>(kern.dW_over_r(norm(pos[0] - pos[j]))));
      const Vec<2> dx = pos[0] - pos[j];
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) M(a, b) -= volume[j] * static_cast<double>(F.back()) * dx[a] * dx[b];
    }
    Mat<2> C;
    ASSERT_TRUE(invert_if_well_conditioned(M, C));
    store(correction[0], C);
    for (std::size_t j = 1; j < n; ++j) store(correction[j], Mat<2>{{1.0 + 0.1 * u(g), 0.2 * u(g), 0.0, 1.0}});
    for (std::size_t j = 1; j < n; ++j) correction[j].c[2] = correction[j].c[1];  // symmetric
    ForceListData<2> d{pos.data(), vel.data(), stress.data(), correction.data(), mass.data(), inv_rho.data(),
                       nullptr, acc.data(), nullptr, n, false, false, log_rho.data(), true};
    d.volume = volume.data();
    Vec<2> a0;
    double du = 0;
    add_force_list(d, 0, js, F, a0, du);
    // Expected: div S + S . k at x_0.
    const Mat<2> Si = as_double(stress[0]);
    Vec<2> expected = contract(Si, k);
    if (linear_stress)
      for (int a = 0; a < 2; ++a) expected[a] += B[a][0][0] + B[a][1][1];
    const double tolerance = (sizeof(ReducedReal) == sizeof(double) ? 1e-9 : 1e-5) * (norm(expected) + 1.0);
    EXPECT_LT(norm(a0 - expected), tolerance) << (linear_stress ? "linear stress" : "constant stress");
    // Each partner's term equals its own list {0}'s (factor F symmetric in the pair).
    for (std::size_t q = 0; q < js.size(); ++q) {
      const std::uint32_t j = js[q], zero = 0;
      std::vector<Vec<2>> acc_j(n);
      ForceListData<2> dj{pos.data(), vel.data(), stress.data(), correction.data(), mass.data(), inv_rho.data(),
                          nullptr, acc_j.data(), nullptr, 0, false, false, log_rho.data(), true};
      dj.volume = volume.data();
      Vec<2> aj;
      add_force_list(dj, j, std::span<const std::uint32_t>(&zero, 1), std::span<const float>(&F[q], 1), aj, du);
      ASSERT_LT(norm(acc[j] - aj), 1e-12 * (norm(aj) + 1e-300)) << "partner " << j;
    }
  }
}

// The consistent force's density ratio without the pair's own terms (PairDensity::Others): each
// density loses the pair partner's kernel term, taken with its own smoothing length, so the ratio
// holds no trace of the pair itself. Hand values with the 2D cubic spline
// W(r, h) = 10 / (7 pi h^2) (1 - 1.5 q^2 + 0.75 q^3), q = r / h < 1.
TEST(ViscousForce, PairDensityLeavesOutThePairsOwnTerms) {
  const double r = 0.05;
  std::vector<double> mass{2.0, 3.0}, without_self{500.0, 200.0};
  const std::vector<KernelScale> scales{{10.0, 10.0 / (7.0 * std::numbers::pi * 0.01)}, {5.0, 10.0 / (7.0 * std::numbers::pi * 0.04)}};
  auto W = [](double rr, double hh) {
    const double q = rr / hh;
    return 10.0 / (7.0 * std::numbers::pi * hh * hh) * (1 - 1.5 * q * q + 0.75 * q * q * q);
  };
  ForceListData<2> d{};
  d.mass = mass.data(), d.scales = scales.data(), d.rho_without_self = without_self.data();
  d.kernel = KernelType::Cubic;
  // W(0.05, 0.1) = 45.4728 x 0.71875 = 32.684; W(0.05, 0.2) = 11.3682 x 0.91797 = 10.436:
  // ln((200 - 2 x 10.436) / (500 - 3 x 32.684)) = ln(179.13 / 401.95) = -0.8082.
  const double expected = std::log((200.0 - 2.0 * W(r, 0.2)) / (500.0 - 3.0 * W(r, 0.1)));
  EXPECT_NEAR(expected, -0.8082, 5e-4);
  const PairValues w = pair_kernel_values(KernelType::Cubic, scales[0], scales[1], r);
  EXPECT_NEAR(others_log_ratio(d, 0, 1, w, 99.0), expected, 1e-13);
  EXPECT_NEAR(others_log_ratio(d, 1, 0, PairValues{w.j, w.i}, 99.0), -expected, 1e-13);  // odd in the pair
  // Nothing left of a density (no other neighbour): the summed densities' ratio.
  without_self = {50.0, 200.0};
  d.rho_without_self = without_self.data();
  EXPECT_EQ(others_log_ratio(d, 0, 1, w, 99.0), 99.0);
}
