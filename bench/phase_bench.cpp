// Microbenchmarks of the phases of one rate evaluation (Google Benchmark), on the ring of the
// default job in cell order: cell build, neighbour search, density, velocity gradient + stress,
// forces (one global h, each phase alone); and a whole leapfrog step with adaptive h (the default
// run's step, the search with the smoothing-length solve included), its phases split by the run's
// own phase timers. Argument: particle count. Each reports particle-updates per second ("items").
//   build/release/bench/phase_bench --benchmark_format=csv > phases.csv
// Threads: OMP_NUM_THREADS (the parallel layer's default).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "evaluate/rate_evaluator.hpp"
#include "integrate/integrator.hpp"
#include "core/vector_isa.hpp"
#include "neighbours/candidate_scan.hpp"
#include "neighbours/cell_grid.hpp"
#include "neighbours/neighbour_lists.hpp"
#include "neighbours/pair_lists.hpp"
#include "physics/density.hpp"
#include "physics/forces.hpp"
#include "physics/viscous_stress.hpp"
#include "problems/ring_setup.hpp"

namespace {
using namespace sphdisk;

constexpr double kNeighbours = 60;
constexpr int kTileCells = 16;  // as a run with constant h uses (evaluate/rate_evaluator.cpp)

// Everything a phase needs, evaluated once up to that phase.
struct Fixture {
  Particles<2> p;
  PhysicsParams phys;
  double h = 0;
  CellGrid<2> grid;
  PairLists pairs;
  PairFactors factors;
  GradientSumsArray<2> sums;
  OverwriteVector<KernelScale> scales;
  ScatterDensityScratch scatter;
  ForceScratch scratch;

  // The neighbour search of a run with constant h: tile order, then each pair once (rate_evaluator.cpp).
  void search() {
    build_tile_order(grid, kTileCells, p.size(), pairs);
    build_half_neighbour_lists(grid, p.pos, 2 * h, pairs.slot, p.size(), pairs.order, pairs.near);
    no_far_pairs(pairs);
  }

  explicit Fixture(std::size_t n) {
    RingSetup setup;
    setup.solution = RingSolution{1e-10, 1.0, 4.7786e-5};
    setup.placement.particles = n;
    h = ring_smoothing_length(setup, kNeighbours);
    phys.nu = setup.solution.viscosity;
    p = make_ring(setup);
    p.gather(build_cell_grid(p.pos, p.id, h).sorted);
    build_cell_grid(p.pos, p.id, h, grid);
    search();
    compute_density(p, StoredPairs{pairs, factors}, KernelAt<CubicSpline, 2>(h));
    compute_viscous_stress(p, StoredPairs{pairs, factors}, phys, sums, scales, scatter);
  }
};

Fixture& fixture(std::size_t n) {  // one per size, built outside the timed loops
  static std::map<std::size_t, std::unique_ptr<Fixture>> cache;
  auto& f = cache[n];
  if (!f) f = std::make_unique<Fixture>(n);
  return *f;
}

void finish(benchmark::State& state, std::size_t n, const PairLists& pairs) {  // pairs: each once
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
  state.counters["pairs_per_s"] = benchmark::Counter(static_cast<double>(pairs.total()) * static_cast<double>(state.iterations()),
                                                      benchmark::Counter::kIsRate);
}

void BM_CellBuild(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  Fixture& f = fixture(n);
  for (auto _ : state) build_cell_grid(f.p.pos, f.p.id, f.h, f.grid);
  finish(state, n, f.pairs);
}

void BM_NeighbourSearch(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  Fixture& f = fixture(n);
  for (auto _ : state) f.search();
  finish(state, n, f.pairs);
}

void BM_Density(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  Fixture& f = fixture(n);
  for (auto _ : state) compute_density(f.p, StoredPairs{f.pairs, f.factors}, KernelAt<CubicSpline, 2>(f.h));
  finish(state, n, f.pairs);
}

void BM_VelocityGradient(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  Fixture& f = fixture(n);
  for (auto _ : state) compute_viscous_stress(f.p, StoredPairs{f.pairs, f.factors}, f.phys, f.sums, f.scales, f.scatter);
  finish(state, n, f.pairs);
}

// Floating-point operations of the force loop (physics/forces.hpp, 2D, pressureless, no force
// correction), counted from the source: per pair g = (x_i - x_j) F (2 sub + 2 mul), X = S_i / rho_j +
// S_j / rho_i (4 components x 3), f = X . g (2 x 3), a_i += m_j f and a_j -= m_i f (2 x 4): 30;
// per particle 1 / rho (1) and the point mass's gravity (|x|^2: 3, sqrt, r^2 r, -GM / that, x * it: 3
// + 1 + 1 + 1 + 2): 9. Divisions and the square root count as one, as in a FLOP count for a peak.
constexpr double kForceFlopsPerPair = 30, kForceFlopsPerParticle = 9;

void BM_Forces(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  Fixture& f = fixture(n);
  for (auto _ : state) compute_accelerations(f.p, StoredPairs{f.pairs, f.factors}, f.phys, f.scratch);
  finish(state, n, f.pairs);
  state.counters["flops_per_s"] = benchmark::Counter(
      (kForceFlopsPerPair * static_cast<double>(f.pairs.total()) + kForceFlopsPerParticle * static_cast<double>(n)) *
          static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate);
}

// Leapfrog steps of the ring with adaptive h, as a run takes them (RateEvaluator: each particle's h
// solved from its value of the previous step during the neighbour search, then the pair loops).
// Counters: seconds per step of each phase (the evaluator's phase timers), so the search with the
// h solve, which the constant-h phases above leave out, is measured too. The ring evolves from
// step to step (the first step solves h from the global h and is not timed).
void BM_AdaptiveStep(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  Particles<2> p = fixture(n).p;
  std::fill(p.h.begin(), p.h.end(), fixture(n).h);  // the start value of the first solve
  PhaseTimers timers;
  RateEvaluator<2> rates(KernelType::Cubic, fixture(n).h, fixture(n).phys, timers, Smoothing::Adaptive, kNeighbours);
  const auto leapfrog = make_integrator<2>(IntegratorParams{}, rates);
  leapfrog->start(p);
  leapfrog->step(p, std::numeric_limits<double>::infinity());
  const std::vector<std::pair<std::string, double>> before = timers.phases();
  for (auto _ : state) leapfrog->step(p, std::numeric_limits<double>::infinity());
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));
  for (const auto& [phase, seconds] : timers.phases()) {
    double earlier = 0;
    for (const auto& [name, s0] : before)
      if (name == phase) earlier = s0;
    state.counters["s_" + phase] = benchmark::Counter(seconds - earlier, benchmark::Counter::kAvgIterations);
  }
}

// One partial evaluation of block timesteps (integrate/block_leapfrog.cpp): the innermost fraction
// 1/range(1) of the particles active (moved to the front), the rest only partners, adaptive h. With
// few active particles this measures what a partial evaluation costs beyond its active particles
// (cell build, inactive partners' searches, passes over all particles); items: active particles.
void BM_PartialEvaluation(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  Particles<2> p = fixture(n).p;
  std::fill(p.h.begin(), p.h.end(), fixture(n).h);
  PhaseTimers timers;
  RateEvaluator<2> rates(KernelType::Cubic, fixture(n).h, fixture(n).phys, timers, Smoothing::Adaptive, kNeighbours);
  rates.evaluate(p);
  // The innermost ones to the front, each part in cell order (as the block integrator keeps each bin).
  const std::size_t active = std::max<std::size_t>(1, n / static_cast<std::size_t>(state.range(1)));
  std::vector<double> r2(n);
  for (std::size_t i = 0; i < n; ++i) r2[i] = norm2(p.pos[i]);
  std::vector<double> sorted = r2;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(active - 1), sorted.end());
  const double edge = sorted[active - 1];
  std::vector<std::uint32_t> inner_first(n);
  for (std::size_t i = 0; i < n; ++i) inner_first[i] = static_cast<std::uint32_t>(i);
  std::stable_partition(inner_first.begin(), inner_first.end(), [&](std::uint32_t i) { return r2[i] <= edge; });
  p.gather(inner_first);
  rates.evaluate(p, active);
  for (auto _ : state) rates.evaluate(p, active);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * active));
}

// The same with the hand-dispatched loops (core/vector_isa.hpp: the candidate scan, the h solve's
// kernel terms, the pair factors, the gradient and force list sums) capped at a narrower path:
// baseline (scalar/SSE2), or AVX2 on a CPU with AVX-512 (whose 512-bit units differ between CPU
// makes, so which path is faster is measured, not assumed). Equal to the uncapped benchmark where
// the CPU has nothing wider than the cap.
template <VectorIsa Cap, void (*Benchmark)(benchmark::State&)>
void capped(benchmark::State& state) {
  limit_vector_isa(Cap);
  Benchmark(state);
  limit_vector_isa(VectorIsa::avx512);
}
void BM_NeighbourSearchBaseline(benchmark::State& state) { capped<VectorIsa::baseline, BM_NeighbourSearch>(state); }
void BM_VelocityGradientBaseline(benchmark::State& state) { capped<VectorIsa::baseline, BM_VelocityGradient>(state); }
void BM_ForcesBaseline(benchmark::State& state) { capped<VectorIsa::baseline, BM_Forces>(state); }
void BM_AdaptiveStepBaseline(benchmark::State& state) { capped<VectorIsa::baseline, BM_AdaptiveStep>(state); }
void BM_NeighbourSearchAvx2(benchmark::State& state) { capped<VectorIsa::avx2, BM_NeighbourSearch>(state); }
void BM_VelocityGradientAvx2(benchmark::State& state) { capped<VectorIsa::avx2, BM_VelocityGradient>(state); }
void BM_ForcesAvx2(benchmark::State& state) { capped<VectorIsa::avx2, BM_Forces>(state); }
void BM_AdaptiveStepAvx2(benchmark::State& state) { capped<VectorIsa::avx2, BM_AdaptiveStep>(state); }

#define SPHDISK_PHASE(bm) BENCHMARK(bm)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->UseRealTime()
SPHDISK_PHASE(BM_CellBuild);
SPHDISK_PHASE(BM_NeighbourSearch);
SPHDISK_PHASE(BM_Density);
SPHDISK_PHASE(BM_VelocityGradient);
SPHDISK_PHASE(BM_Forces);
SPHDISK_PHASE(BM_AdaptiveStep);
BENCHMARK(BM_PartialEvaluation)->ArgsProduct({{100000, 1000000}, {1, 10, 500}})->Unit(benchmark::kMillisecond)->UseRealTime();
SPHDISK_PHASE(BM_NeighbourSearchBaseline);
SPHDISK_PHASE(BM_VelocityGradientBaseline);
SPHDISK_PHASE(BM_ForcesBaseline);
SPHDISK_PHASE(BM_AdaptiveStepBaseline);
SPHDISK_PHASE(BM_NeighbourSearchAvx2);
SPHDISK_PHASE(BM_VelocityGradientAvx2);
SPHDISK_PHASE(BM_ForcesAvx2);
SPHDISK_PHASE(BM_AdaptiveStepAvx2);

}  // namespace

BENCHMARK_MAIN();
