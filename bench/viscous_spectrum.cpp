// The spectrum's ends of the viscous rates, the linear map v -> a_visc(v) (eqs. 6-8 at frozen
// positions, gravity left out) on the ring at tau = 0.018, by power iteration, in units of
// nu / h_min^2 (h_min the smallest smoothing length):
//   - the eigenvalue of largest modulus (negative: the stiffest damped mode). An explicit
//     (forward-Euler) update of the viscous rates is stable for steps dt <= 2 / |lambda|; this is
//     what the super-steps' stage count (integrate/super_steps.hpp) measures steps against;
//   - the one of largest real part (power iteration on L + |lambda| I): a positive one is a velocity
//     pattern the discrete rates amplify instead of damping.
//   build/release/bench/viscous_spectrum [--particles N] [--neighbours 60] [--iterations 200] [--seed 1]
//       [--force consistent|conservative] [--pair-density summation|others] [--gradient-correction mixed|linear|none]
//       [--stratified 0|1]
// Prints both, each with the ratio of its Rayleigh quotient (mass-weighted) to the norm growth (1
// when converged to a real eigenvalue), and 2 / |lambda| in h_min^2 / nu.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "evaluate/rate_evaluator.hpp"
#include "neighbours/cell_grid.hpp"
#include "problems/ring_setup.hpp"

using namespace sphdisk;

int main(int argc, char** argv) {
  std::size_t particles = 30000;
  double neighbours = 60;
  int iterations = 200;
  unsigned seed = 1;
  ViscousForce force = ViscousForce::Consistent;
  PairDensity density = PairDensity::Summation;
  GradientCorrection correction = PhysicsParams{}.gradient_correction;  // the default: linear
  bool stratified = false;  // radii at (k + U)/N quantiles (problem.placement = "stratified")
  for (int k = 1; k + 1 < argc; k += 2) {
    const std::string key = argv[k], val = argv[k + 1];
    if (key == "--particles") particles = std::stoul(val);
    else if (key == "--neighbours") neighbours = std::stod(val);
    else if (key == "--iterations") iterations = std::stoi(val);
    else if (key == "--seed") seed = static_cast<unsigned>(std::stoul(val));
    else if (key == "--force") force = val == "conservative" ? ViscousForce::Conservative : ViscousForce::Consistent;
    else if (key == "--gradient-correction" && (val == "none" || val == "linear" || val == "mixed"))
      correction = val == "none" ? GradientCorrection::None : val == "linear" ? GradientCorrection::Linear : GradientCorrection::Mixed;
    else if (key == "--stratified") stratified = val != "0";
    else if (key == "--pair-density") density = val == "others" ? PairDensity::Others : PairDensity::Summation;
    else {
      std::fprintf(stderr, "viscous_spectrum: unknown option or value %s (use --particles --neighbours --iterations --seed --force "
                   "--pair-density --gradient-correction none|linear|mixed --stratified)\n", key.c_str());
      return 2;
    }
  }
  RingSetup setup;
  setup.solution = RingSolution{1e-10, 1.0, 4.7786e-5};
  setup.placement.particles = particles;
  setup.placement.stratified = stratified;
  const double h = ring_smoothing_length(setup, neighbours);
  PhysicsParams phys;
  phys.nu = setup.solution.viscosity;
  phys.viscous_force = force;
  phys.pair_density = density;
  phys.gradient_correction = correction;
  Particles<2> p = make_ring(setup);
  p.gather(build_cell_grid(p.pos, p.id, h).sorted);
  std::fill(p.h.begin(), p.h.end(), h);
  PhaseTimers timers;
  RateEvaluator<2> rates(KernelType::Cubic, h, phys, timers, Smoothing::Adaptive, neighbours);
  rates.include_gravity(false);
  // The map is linear in v: start from random velocities and apply it (plus shift x identity)
  // again and again.
  std::mt19937_64 g(seed);
  std::normal_distribution<double> normal;
  const auto mass_dot = [&](const std::vector<Vec<2>>& a, const std::vector<Vec<2>>& b) {
    double s = 0;
    for (std::size_t i = 0; i < p.size(); ++i) s += p.mass[i] * dot(a[i], b[i]);
    return s;
  };
  std::vector<Vec<2>> v(p.size());
  const auto end_of_spectrum = [&](double shift, double& growth) {
    for (auto& x : p.vel) x = Vec<2>{normal(g), normal(g)};
    double lambda = 0;
    for (int it = 0; it < iterations; ++it) {
      v = p.vel;
      const double vv = mass_dot(v, v);
      rates.evaluate(p);
      for (std::size_t i = 0; i < p.size(); ++i) p.acc[i] += v[i] * shift;
      lambda = mass_dot(v, p.acc) / vv - shift;  // Rayleigh quotient of L
      growth = std::sqrt(mass_dot(p.acc, p.acc) / vv);
      const double scale = 1.0 / std::sqrt(mass_dot(p.acc, p.acc));
      for (std::size_t i = 0; i < p.size(); ++i) p.vel[i] = p.acc[i] * scale;
    }
    return lambda;
  };
  double growth = 0;
  const double largest = end_of_spectrum(0.0, growth);
  const double converged = std::abs(largest) / growth;
  double shifted_growth = 0;
  const double rightmost = end_of_spectrum(std::abs(largest), shifted_growth);
  const double shifted_converged = (rightmost + std::abs(largest)) / shifted_growth;
  // Where the rightmost mode lives: its mass-weighted energy's mean radius and spread, and the mean h there.
  double e = 0, er = 0, er2 = 0, eh = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double w = p.mass[i] * dot(p.vel[i], p.vel[i]), r = norm(p.pos[i]);  // (the point mass at the origin)
    e += w;
    er += w * r;
    er2 += w * r * r;
    eh += w * p.h[i];
  }
  // Its strongest particle: the distance to its nearest neighbour, against h and the mean spacing.
  std::size_t top = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (dot(p.vel[i], p.vel[i]) * p.mass[i] > dot(p.vel[top], p.vel[top]) * p.mass[top]) top = i;
  double nearest = 1e300;
  for (std::size_t j = 0; j < p.size(); ++j)
    if (j != top) nearest = std::min(nearest, norm(p.pos[j] - p.pos[top]));
  const double spacing = p.h[top] / std::sqrt(neighbours / (4.0 * 3.141592653589793));  // (60 in (2h)^2 pi)
  double share = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (norm(p.pos[i] - p.pos[top]) < 2.0 * p.h[top]) share += p.mass[i] * dot(p.vel[i], p.vel[i]);
  std::printf("rightmost mode: strongest particle's nearest neighbour at %.3g h (%.3g mean spacings); %.3f of the "
              "mode's energy within its 2h\n", nearest / p.h[top], nearest / spacing, share / e);
  const double h_min = *std::min_element(p.h.begin(), p.h.end());
  std::printf("rightmost mode: radius %.4g +- %.3g, mean h there %.3g h_min\n", er / e, std::sqrt(std::max(0.0, er2 / e - er * er / e / e)),
              eh / e / h_min);
  const double unit = phys.nu / (h_min * h_min);
  std::printf("particles %zu neighbours %g: largest |lambda| %.4g nu/h_min^2 (converged %.4f; explicit limit 2/|lambda| = "
              "%.4g h_min^2/nu); largest real part %.4g nu/h_min^2 (converged %.4f)\n",
              particles, neighbours, largest / unit, converged, 2.0 / (std::abs(largest) / unit), rightmost / unit,
              shifted_converged);
  return 0;
}
