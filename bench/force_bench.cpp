// Throughput of one full force evaluation (cell build + neighbour lists + density + velocity
// gradient/stress + accelerations) on the ring at tau = 0.018, for the parallel code at several
// thread counts and for the symmetric sequential variant (P98 Figs. 3 and 4). Writes CSV rows:
//   variant,threads,particles,neighbours,seconds_per_evaluation,particle_updates_per_second,
//   pair_interactions_per_second,best_seconds_per_evaluation
// (seconds: median of --repeats evaluations, the variants taking turns), where neighbours = 2 x pairs / particles and pair interactions = pairs x 3 pair loops (density,
// gradient, force), each pair evaluated once per loop (the symmetric variant does the same).
#include <chrono>
#include <cmath>
#include <algorithm>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "evaluate/rate_evaluator.hpp"
#include "neighbours/cell_grid.hpp"
#include "parallel/loops.hpp"
#include "problems/ring_setup.hpp"
#include "symmetric_sequential.hpp"

using namespace sphdisk;
using Clock = std::chrono::steady_clock;

namespace {

struct Args {
  std::size_t particles = 100000;
  double neighbours = 60;
  std::vector<int> threads = {1, 2};
  int repeats = 11;
  bool symmetric = true;
  bool adaptive = true;
};

Args parse(int argc, char** argv) {
  Args a;
  for (int k = 1; k + 1 < argc; k += 2) {
    const std::string key = argv[k], val = argv[k + 1];
    if (key == "--particles") a.particles = std::stoul(val);
    else if (key == "--neighbours") a.neighbours = std::stod(val);
    else if (key == "--repeats") a.repeats = std::stoi(val);
    else if (key == "--symmetric") a.symmetric = val != "0";
    else if (key == "--adaptive") a.adaptive = val != "0";
    else if (key == "--threads") {
      a.threads.clear();
      std::size_t pos = 0;
      while (pos < val.size()) {
        const std::size_t comma = val.find(',', pos);
        a.threads.push_back(std::stoi(val.substr(pos, comma - pos)));
        pos = comma == std::string::npos ? val.size() : comma + 1;
      }
    } else {
      std::fprintf(stderr, "force_bench: unknown option %s (use --particles --neighbours --threads 1,2 --repeats --symmetric 0|1 --adaptive 0|1)\n", key.c_str());
      std::exit(2);
    }
  }
  return a;
}

}  // namespace

int main(int argc, char** argv) {
  const Args a = parse(argc, argv);
  RingSetup setup;
  setup.solution = RingSolution{1e-10, 1.0, 4.7786e-5};
  setup.placement.particles = a.particles;
  const double h = ring_smoothing_length(setup, a.neighbours);
  PhysicsParams phys;
  phys.nu = setup.solution.viscosity;
  // In cell order, as the simulation keeps them (it reorders every few steps for cache locality).
  Particles<2> initial = make_ring(setup);
  initial.gather(build_cell_grid(initial.pos, initial.id, h).sorted);

  Particles<2> p = initial;
  PhaseTimers timers;
  RateEvaluator<2> rates(KernelType::Cubic, h, phys, timers);
  rates.evaluate(p);
  const double pairs = static_cast<double>(rates.pair_lists().total());
  const double n = static_cast<double>(a.particles);
  std::printf("variant,threads,particles,neighbours,seconds_per_evaluation,particle_updates_per_second,"
              "pair_interactions_per_second,best_seconds_per_evaluation\n");
  auto row = [&](const char* variant, int threads, double sec, double best, double pairs_evaluated) {
    std::printf("%s,%d,%zu,%.1f,%.6g,%.6g,%.6g,%.6g\n", variant, threads, a.particles, 2 * pairs_evaluated / n, sec,
                n / sec, 3 * pairs_evaluated / sec, best);
    std::fflush(stdout);
  };
  // The variants take turns, one evaluation each, and report their median (and best) time: on a
  // shared machine whose speed drifts by 10-30% over seconds, all variants then see the same
  // phases, and the median does not favour the variant that needs the fewest quiet cores.
  struct Variant {
    std::string name;
    int threads;
    std::function<void()> evaluate;
    std::function<double()> pairs;
    std::vector<double> seconds;
  };
  std::vector<Variant> variants;
  for (int t : a.threads)
    variants.push_back({"parallel", t, [&] { rates.evaluate(p); }, [&] { return static_cast<double>(rates.pair_lists().total()); }, {}});
  // Adaptive smoothing lengths (the default of a run). The warm-up evaluation converges h; in a
  // run particles move between evaluations, so the Newton solve takes ~2 iterations instead of 1
  // here: these rows slightly underestimate its cost.
  Particles<2> q = initial;
  std::fill(q.h.begin(), q.h.end(), h);
  RateEvaluator<2> adaptive(KernelType::Cubic, h, phys, timers, Smoothing::Adaptive, a.neighbours);
  if (a.adaptive)
    for (int t : a.threads)
      variants.push_back({"parallel_adaptive", t, [&] { adaptive.evaluate(q); },
                          [&] { return static_cast<double>(adaptive.pair_lists().total()); }, {}});
  Particles<2> ps = initial;
  bench::SymmetricSequential sym;
  if (a.symmetric)
    variants.push_back({"symmetric_sequential", 1, [&] { sym.evaluate(ps, h, phys); }, [&] { return pairs; }, {}});
  for (Variant& v : variants) {  // warm-up: first touch of buffers
    par::set_threads(v.threads);
    v.evaluate();
  }
  for (int r = 0; r < a.repeats; ++r)
    for (Variant& v : variants) {
      par::set_threads(v.threads);
      const auto t0 = Clock::now();
      v.evaluate();
      v.seconds.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
    }
  par::set_threads(0);
  for (Variant& v : variants) {
    std::sort(v.seconds.begin(), v.seconds.end());
    const std::size_t k = v.seconds.size();
    const double median = k % 2 ? v.seconds[k / 2] : 0.5 * (v.seconds[k / 2 - 1] + v.seconds[k / 2]);
    row(v.name.c_str(), v.threads, median, v.seconds.front(), v.pairs());
  }
  if (a.symmetric) {
    // Same physics: accelerations agree to round-off.
    double worst = 0, scale = 0;
    for (std::size_t i = 0; i < p.size(); ++i) scale = std::max(scale, norm(p.acc[i]));
    for (std::size_t i = 0; i < p.size(); ++i) worst = std::max(worst, norm(p.acc[i] - ps.acc[i]));
    std::fprintf(stderr, "symmetric vs parallel: max |a difference| / max |a| = %.2e\n", worst / scale);
    if (worst > 1e-6 * scale) return 1;  // single-precision pair factors, summed in another order
  }
  return 0;
}
