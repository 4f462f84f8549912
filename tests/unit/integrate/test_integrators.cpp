// Time integration: with nu = 0 the ring's particles are pure Kepler orbits and must stay on their
// circles (docs/physics.md sec. 3 "accuracy trap"); rate evaluation and stepping give the same bits
// for any thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "evaluate/rate_evaluator.hpp"
#include "integrate/integrator.hpp"
#include "parallel/loops.hpp"
#include "problems/ring_setup.hpp"

using namespace sphdisk;

namespace {

RingSetup small_ring(std::size_t n, double nu) {
  RingSetup s;
  s.solution = RingSolution{1e-10, 1.0, nu};
  s.placement.particles = n;
  return s;
}

struct Drift {
  double guiding_centre;  // max |r_g(end) - r_g(0)| / r_g(0) per orbit, r_g = j^2 / (G M)
  double semi_major;      // max |<a>_last - <a>_first| / a per orbit, a = -G M / (2 E), orbit-averaged
};

// Secular radial drift of Kepler orbits (nu = 0), per orbit at r0, over `orbits` orbits. The
// guiding-centre radius is the low-noise measure of radial drift (docs/physics.md sec. 4); the
// orbit-averaged semi-major axis also catches energy drift.
Drift kepler_drift(const IntegratorParams& ip, std::size_t n, double orbits) {
  const RingSetup s = small_ring(n, 0.0);
  Particles<2> p = make_ring(s);
  const double h = ring_smoothing_length(s, 40);
  PhysicsParams phys;  // nu = 0: gravity only; the SPH stages still run (and must add nothing)
  PhaseTimers timers;
  RateEvaluator<2> rates(KernelType::Cubic, h, phys, timers);
  auto integ = make_integrator<2>(ip, rates);
  integ->start(p);
  auto j_of = [&](std::size_t i) { return p.pos[i][0] * p.vel[i][1] - p.pos[i][1] * p.vel[i][0]; };
  auto a_of = [&](std::size_t i) { return -1.0 / (2.0 * (0.5 * norm2(p.vel[i]) - 1.0 / norm(p.pos[i]))); };
  std::vector<double> j0(n), a_first(n, 0), a_last(n, 0);
  for (std::size_t i = 0; i < n; ++i) j0[p.id[i] - 1] = j_of(i);
  const double period = 2 * std::numbers::pi, t_end = orbits * period;
  double t = 0, w_first = 0, w_last = 0;
  while (t < t_end) {
    const double dt = integ->step(p, t_end - t);
    t += dt;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (t <= period) a_first[p.id[i] - 1] += a_of(i) * dt;
      if (t > t_end - period) a_last[p.id[i] - 1] += a_of(i) * dt;
    }
    if (t <= period) w_first += dt;
    if (t > t_end - period) w_last += dt;
  }
  Drift d{0, 0};
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k = p.id[i] - 1;
    const double j = j_of(i);
    d.guiding_centre = std::max(d.guiding_centre, std::abs(j * j - j0[k] * j0[k]) / (j0[k] * j0[k]) / orbits);
    const double a = a_first[k] / w_first, b = a_last[k] / w_last;
    d.semi_major = std::max(d.semi_major, std::abs(b - a) / a / (orbits - 1));
  }
  return d;
}

void expect_kepler_rings_on_their_circles(const IntegratorParams& ip, std::size_t n, double orbits, const char* name) {
  const Drift d = kepler_drift(ip, n, orbits);
  std::printf("%s: guiding-centre drift %.3e, semi-major-axis drift %.3e per orbit\n", name, d.guiding_centre, d.semi_major);
  EXPECT_LE(d.guiding_centre, 1e-6);
  EXPECT_LE(d.semi_major, 1e-6);
}

}  // namespace

TEST(Integrators, LeapfrogKeepsKeplerRingsOnTheirCircles) {
  expect_kepler_rings_on_their_circles(IntegratorParams{}, 500, 10, "leapfrog");  // the default, orbital factor 0.25
}

TEST(Integrators, RespaKeepsKeplerRingsOnTheirCircles) {
  IntegratorParams ip;
  ip.scheme = Scheme::Respa;  // with nu = 0 the hydro step is the orbital limit; gravity substepped inside
  expect_kepler_rings_on_their_circles(ip, 500, 10, "respa");
}

// Block timesteps with nu = 0: the orbital limit puts the particles in several bins; the integer
// time line must keep each on its circle all the same.
TEST(Integrators, BlockTimestepsKeepKeplerRingsOnTheirCircles) {
  IntegratorParams ip;
  ip.scheme = Scheme::Block;
  expect_kepler_rings_on_their_circles(ip, 500, 10, "block");
}

TEST(Integrators, RungeKuttaWithTightToleranceKeepsKeplerRings) {
  IntegratorParams ip;
  ip.scheme = Scheme::RK45;
  ip.tolerance = 1e-9;
  expect_kepler_rings_on_their_circles(ip, 300, 6, "rk45 1e-9");
}

// A loose tolerance visibly spoils the orbits (the paper's 500k run, P98 sec. 5.3): the error
// control must respond to the tolerance, so a looser tolerance drifts more.
TEST(Integrators, LooserToleranceDriftsMore) {
  IntegratorParams tight, loose;
  tight.scheme = loose.scheme = Scheme::RK45;
  tight.tolerance = 1e-8;
  loose.tolerance = 1e-4;
  const Drift t = kepler_drift(tight, 200, 4), l = kepler_drift(loose, 200, 4);
  std::printf("rk45: drift %.3e at 1e-8, %.3e at 1e-4 per orbit\n", t.guiding_centre, l.guiding_centre);
  EXPECT_LT(t.guiding_centre, l.guiding_centre);
  EXPECT_GT(l.guiding_centre, 1e-6);  // the paper's failure mode is visible at a loose tolerance
}

TEST(Integrators, SameBitsForAnyThreadCount) {
  for (Scheme scheme : {Scheme::Leapfrog, Scheme::Respa, Scheme::Block, Scheme::RK45}) {
    std::vector<Particles<2>> results;
    for (int threads : {1, 2, 3, 4}) {
      par::set_threads(threads);
      const RingSetup s = small_ring(3000, 4.778e-5);
      Particles<2> p = make_ring(s);
      PhysicsParams phys;
      phys.nu = 4.778e-5;
      phys.evolve_energy = true;
      PhaseTimers timers;
      RateEvaluator<2> rates(KernelType::Cubic, ring_smoothing_length(s, 60), phys, timers);
      IntegratorParams ip;
      ip.scheme = scheme;
      auto integ = make_integrator<2>(ip, rates);
      integ->start(p);
      for (int k = 0; k < 10; ++k) integ->step(p, 1.0);
      results.push_back(p);
    }
    par::set_threads(0);
    for (std::size_t r = 1; r < results.size(); ++r) {
      EXPECT_EQ(results[r].pos, results[0].pos) << "threads " << r + 1;
      EXPECT_EQ(results[r].vel, results[0].vel) << "threads " << r + 1;
      EXPECT_EQ(results[r].rho, results[0].rho) << "threads " << r + 1;
      EXPECT_EQ(results[r].u, results[0].u) << "threads " << r + 1;
    }
  }
}

namespace {

// A viscous ring advanced to t_end with hydro steps of at most dt_max (respa; gravity substeps so
// fine that their error is negligible), particles returned in ID order.
Particles<2> viscous_ring_after(double t_end, double dt_max, Scheme scheme, double orbital_factor = 1.0,
                                std::size_t* updates = nullptr) {
  const RingSetup s = small_ring(1500, 4.778e-5);
  Particles<2> p = make_ring(s);
  PhysicsParams phys;
  phys.nu = 4.778e-5;
  PhaseTimers timers;
  RateEvaluator<2> rates(KernelType::Cubic, ring_smoothing_length(s, 60), phys, timers);
  IntegratorParams ip;
  ip.scheme = scheme;
  ip.factors.orbital = orbital_factor;
  ip.factors.force = ip.factors.viscous = 1.0;  // dt_max binds unless the orbital limit is smaller
  ip.factors.substep = 2e-3;
  ip.dt_max = dt_max;
  auto integ = make_integrator<2>(ip, rates);
  integ->start(p);
  for (double t = 0; t < t_end * (1 - 1e-12);) t += integ->step(p, t_end - t);
  if (updates) *updates = rates.particle_updates();
  Particles<2> sorted = p;
  for (std::size_t i = 0; i < p.size(); ++i) {
    sorted.pos[p.id[i] - 1] = p.pos[i];
    sorted.vel[p.id[i] - 1] = p.vel[i];
  }
  return sorted;
}

double largest_velocity_difference(const Particles<2>& a, const Particles<2>& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, norm(a.vel[i] - b.vel[i]));
  return d;
}

}  // namespace

// Splitting the point-mass gravity from the SPH forces (Strang splitting, symmetric) keeps the
// scheme second order in the hydrodynamic step: the error falls as dt^2. Measured as the slope of
// log error against log dt over four halvings (t/4 .. t/32) against the same scheme at t/256, whose
// own error is 1/64 of the finest: the error of single halvings falls by factors that scatter
// (1.7 to 7.6 with the consistent divergence of eq. 6, the default), the slope over four does not.
TEST(Integrators, RespaIsSecondOrderInTheHydroStep) {
  const double t_end = 0.4;
  const Particles<2> reference = viscous_ring_after(t_end, t_end / 256, Scheme::Respa);
  double sx = 0, sy = 0, sxx = 0, sxy = 0, finest = 0;
  for (int k : {4, 8, 16, 32}) {
    const double error = largest_velocity_difference(viscous_ring_after(t_end, t_end / k, Scheme::Respa), reference);
    std::printf("respa velocity error at dt = t/%d: %.3e\n", k, error);
    ASSERT_GT(error, 0.0);
    const double x = std::log(1.0 / k), y = std::log(error);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
    finest = error;
  }
  const double slope = (4 * sxy - sx * sy) / (4 * sxx - sx * sx);
  std::printf("respa: error ~ dt^%.2f\n", slope);
  EXPECT_GT(slope, 1.6);
  EXPECT_LT(slope, 2.5);
  // and to the plain leapfrog's answer (gravity and SPH forces in one step, so it needs a step
  // fine enough for the orbits too)
  const double schemes = largest_velocity_difference(viscous_ring_after(t_end, t_end / 512, Scheme::Leapfrog), reference);
  std::printf("respa at dt = t/256 vs leapfrog at t/512: %.3e\n", schemes);
  EXPECT_LT(schemes, finest);
}

// With every particle in one bin (dt_max below every particle's own limit) block timesteps are the
// respa scheme, bit for bit.
TEST(Integrators, BlockTimestepsInOneBinAreRespa) {
  const Particles<2> block = viscous_ring_after(0.2, 0.05, Scheme::Block);
  const Particles<2> respa = viscous_ring_after(0.2, 0.05, Scheme::Respa);
  EXPECT_EQ(block.pos, respa.pos);
  EXPECT_EQ(block.vel, respa.vel);
}

// Particles in several bins (orbital limit 0.1 / Omega: two bins over this ring): the error stays
// close to that of one global step at the smallest particle step (3x; inactive neighbours' stale
// h and rho remain; without turning their stress with the orbit it was 24x, above the error of
// global steps of t/4), while fewer particles are updated.
TEST(Integrators, BlockTimestepsAreAccurateAndUpdateFewerParticles) {
  const double t_end = 0.8;
  const Particles<2> reference = viscous_ring_after(t_end, t_end / 256, Scheme::Respa);
  std::size_t block_updates = 0, global_updates = 0;
  const Particles<2> block = viscous_ring_after(t_end, 1.0, Scheme::Block, 0.1, &block_updates);
  const Particles<2> global = viscous_ring_after(t_end, 1.0, Scheme::Respa, 0.1, &global_updates);
  const double e_block = largest_velocity_difference(block, reference);
  const double e_global = largest_velocity_difference(global, reference);
  const double e_coarse = largest_velocity_difference(viscous_ring_after(t_end, t_end / 4, Scheme::Respa), reference);
  std::printf("block: error %.3e, %zu particle updates; global smallest step: error %.3e, %zu updates; "
              "global step t/4: error %.3e\n", e_block, block_updates, e_global, global_updates, e_coarse);
  EXPECT_LT(e_block, 3 * e_global);
  EXPECT_LT(e_block, e_coarse);
  EXPECT_LT(block_updates, global_updates * 3 / 4);
  EXPECT_GT(e_block, 0.0);
}

// The integrator's own per-particle state is counted (ranks.json memory_bytes.integrator): after a
// step, at least the arrays each scheme keeps per particle whatever the equation of state (leapfrog:
// the half-step velocity; Runge-Kutta 4(5): the initial positions, velocities and accelerations and
// six stages' rates of x and v). (Block steps keep theirs in the particles' kStepState fields,
// counted with the particles.)
TEST(Integrators, ReportTheMemoryOfTheirPerParticleState) {
  const RingSetup s = small_ring(400, 1e-3);
  PhysicsParams phys;
  phys.nu = 1e-3;
  PhaseTimers timers;
  const std::pair<Scheme, std::size_t> expected[] = {
      {Scheme::Leapfrog, sizeof(Vec<2>)},
      {Scheme::RK45, 3 * sizeof(Vec<2>) + 6 * 2 * sizeof(Vec<2>)}};
  for (const auto& [scheme, per_particle] : expected) {
    Particles<2> p = make_ring(s);
    RateEvaluator<2> rates(KernelType::Cubic, ring_smoothing_length(s, 40), phys, timers);
    IntegratorParams ip;
    ip.scheme = scheme;
    auto integ = make_integrator<2>(ip, rates);
    integ->start(p);
    integ->step(p, 1e-3);
    EXPECT_GE(integ->bytes(), per_particle * p.size()) << static_cast<int>(scheme);
    EXPECT_LT(integ->bytes(), 4 * per_particle * p.size()) << static_cast<int>(scheme);
  }
}

// Block cycles report between their ticks (Integrator::on_substep): times inside the cycle,
// increasing, never its end; the results are those without the hook; and a hook that throws
// abandons the step by its exception (how a second stop signal ends a long cycle).
// A ring whose block cycles have several bins, for the tests of what happens between their ticks.
struct SeveralBinRing {
  RingSetup s = small_ring(1500, 4.778e-5);
  PhysicsParams phys = [] {
    PhysicsParams p;
    p.nu = 4.778e-5;
    return p;
  }();
  IntegratorParams ip = [] {
    IntegratorParams i;
    i.scheme = Scheme::Block;
    i.factors.orbital = 0.1;  // several bins
    return i;
  }();
  RateEvaluator<2> rates(PhaseTimers& timers) const {
    return RateEvaluator<2>(KernelType::Cubic, ring_smoothing_length(s, 60), phys, timers);
  }
};

TEST(Integrators, BlockCyclesCallTheSubstepHookBetweenTicks) {
  const SeveralBinRing ring;
  const RingSetup& s = ring.s;
  const auto run_cycle = [&](const Integrator<2>::SubstepHook& hook, Particles<2>& p) {
    PhaseTimers timers;
    RateEvaluator<2> rates = ring.rates(timers);
    auto integ = make_integrator<2>(ring.ip, rates);
    if (hook) integ->on_substep(hook);
    integ->start(p);
    return integ->step(p, 1.0);
  };
  Particles<2> plain = make_ring(s), hooked = make_ring(s);
  run_cycle({}, plain);
  std::vector<double> done;
  double cycle = 0;
  const double length = run_cycle([&](double d, double l) { done.push_back(d), cycle = l; }, hooked);
  ASSERT_GE(done.size(), 2u);  // several bins: several ticks
  EXPECT_EQ(cycle, length);
  for (std::size_t k = 0; k < done.size(); ++k) {
    EXPECT_GT(done[k], k > 0 ? done[k - 1] : 0.0);
    EXPECT_LT(done[k], length);
  }
  EXPECT_EQ(plain.pos, hooked.pos);
  EXPECT_EQ(plain.vel, hooked.vel);

  struct Abandon {};
  Particles<2> abandoned = make_ring(s);
  EXPECT_THROW(run_cycle([](double, double) { throw Abandon{}; }, abandoned), Abandon);
}

// A block cycle left between two of its ticks and continued by another integrator from what a
// checkpoint written there holds (the particles, with their steps in the kStepState fields, in
// another memory order as after a read by several ranks, and the cycle's state) ends with the
// particles of the uninterrupted cycle, bit for bit; an integrator without such cycles refuses that
// state with a UserError.
TEST(Integrators, BlockCycleLeftBetweenTicksContinuesBitForBit) {
  const SeveralBinRing ring;
  IntegratorParams ip = ring.ip;
  PhaseTimers timers;
  RateEvaluator<2> rates = ring.rates(timers);
  Particles<2> plain = make_ring(ring.s);
  auto integ = make_integrator<2>(ip, rates);
  integ->start(plain);
  Particles<2> left = plain;
  std::vector<double> done;
  integ->on_substep([&](double d, double) { done.push_back(d); });
  const double length = integ->step(plain, 1.0);
  ASSERT_GE(done.size(), 3u);
  std::printf("block cycle of %zu ticks, left after the first\n", done.size() + 1);

  struct Leave {};
  integ->on_substep([&](double, double) { throw Leave{}; });  // after the first tick
  integ->start(left);
  ASSERT_THROW(integ->step(left, 1.0), Leave);
  ASSERT_TRUE(integ->inside_step());
  const std::vector<double> state = integ->step_state();
  std::vector<std::uint32_t> reversed(left.size());  // another order
  for (std::size_t i = 0; i < left.size(); ++i) reversed[i] = static_cast<std::uint32_t>(left.size() - 1 - i);
  left.gather(reversed);

  RateEvaluator<2> fresh_rates = ring.rates(timers);
  auto resumed = make_integrator<2>(ip, fresh_rates);
  resumed->resume_inside_step(state);
  EXPECT_TRUE(resumed->inside_step());
  EXPECT_EQ(resumed->step(left, 1.0), length);
  EXPECT_FALSE(resumed->inside_step());
  const auto by_id = [](Particles<2>& p) {
    std::vector<std::uint32_t> order(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) order[i] = static_cast<std::uint32_t>(i);
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return p.id[a] < p.id[b]; });
    p.gather(order);
  };
  by_id(plain);
  by_id(left);
  EXPECT_EQ(plain.pos, left.pos);
  EXPECT_EQ(plain.vel, left.vel);
  EXPECT_EQ(plain.acc, left.acc);

  ip.scheme = Scheme::Leapfrog;
  auto other = make_integrator<2>(ip, fresh_rates);
  EXPECT_THROW(other->resume_inside_step(state), UserError);
  EXPECT_THROW(resumed->resume_inside_step({length, 0.0}), UserError);  // no tick done: not inside
}
