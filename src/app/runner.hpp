#pragma once
// One run from a state (fresh or checkpointed) to the last output time (runner.cpp): the step loop,
// the output and checkpoint cadence, stop signals, progress lines, the diagnostics rows and the
// per-rank records. run_simulation and resume_simulation (simulation.cpp) set it up.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "app/run_records.hpp"
#include "app/run_setup.hpp"
#include "app/simulation.hpp"
#include "core/config.hpp"
#include "core/particles.hpp"
#include "domain/distributed_domain.hpp"
#include "evaluate/rate_evaluator.hpp"
#include "integrate/integrator.hpp"
#include "io/checkpoint.hpp"
#include "io/snapshot.hpp"
#include "parallel/timers.hpp"

namespace sphdisk {

// The run's threads, vector instructions and trace as the configuration and options ask; clears
// the count of stop signals heard.
void apply_run_options(const Config& cfg, const RunOptions& opts);

// D: the run's dimension (sph.dimension), 2 or 3.
template <int D>
class Runner {
 public:
  using Clock = std::chrono::steady_clock;

  Runner(const Config& cfg, const RunOptions& opts, std::string dir, Particles<D> p, RunState state);

  // A fresh run: rates of the initial state, snapshot_000, first diagnostics row.
  void start();

  // A resumed run: the checkpoint holds the rates (acc, du_dt), the integrator state and, where
  // the integrator needs it, the rest of the last evaluation (kRateState). A checkpoint without the
  // latter (written by another scheme, or before sphdisk stored it) is continued with the rates
  // evaluated anew: correct, but not bit for bit the run that wrote it.
  // A checkpoint written inside a block cycle also holds the particles' steps in it (kStepState) and
  // the cycle's state: the first step continues that cycle.
  void restart();

  RunSummary advance();

 private:
  bool distributed() const { return domain_.comm().size() > 1; }
  bool root() const { return domain_.comm().is_root(); }
  std::size_t global_count() const { return domain_.comm().sum(p_.size()); }

  // Between steps: particles go to the ranks owning their cells, in equal numbers.
  void rebalance() {
    if (!distributed()) return;
    ScopedPhase timer(timers_, "communication");
    domain_.rebalance(p_, s_.smoothing_length);
  }

  // A 3D disc whose kernels are taller than its scale height H = c_s / Omega for more than half its
  // particles at the start: its vertical structure is unresolved and the viscous spreading rate not
  // converged (docs/validation.md, "The rate a ring with pressure should have"); says so once.
  void warn_if_vertically_unresolved();

  // Removes accreted particles; the tallies are added in particle-ID order, so they do not depend
  // on which rank held which particle (a step may accrete several).
  void accrete_all();

  template <class F>
  void on_root(F&& write) {
    run_on_root(domain_.comm(), write);
  }

  void open_diagnostics();

  void write_output(std::size_t k);

  // Stops on NaN/Inf, keeping the evidence in a debug dump; the last good checkpoint is untouched.
  void check_finite_or_dump();

  // Between steps, or inside one between its substeps (a block cycle: the particles' steps and the
  // cycle's state go in too; time and step stay those before the cycle).
  void write_checkpoint_now();

  void diagnostics_row(double dt);

  RunCounters counters_now() const {
    return {s_.step, rates_.evaluations(), rates_.particle_updates(), rates_.pair_interactions(),
            rates_.smoothing_length_solves(), rates_.smoothing_length_sums(), domain_.traffic()};
  }

  // Per rank: owned particles, ghosts, peak memory and phase timers (load imbalance and
  // communication share per phase; bench/mpi_scaling.sh reads it). Collective; the text on rank 0.
  std::string ranks_json() const;

  double wall() const { return std::chrono::duration<double>(Clock::now() - wall_start_).count(); }

  // Where the root process's lines go besides run.log: stderr, unless --quiet.
  std::FILE* terminal() const { return opts_.quiet ? nullptr : stderr; }

  // A progress line at most every output.progress_interval seconds: at the end of a step, or
  // inside one (`within`: the fraction of the step's time done, `in_step` the particle updates so
  // far) at simulated time `time`. Into run.log also with --quiet.
  void progress(long long step, double time, double dt, double within = -1, std::size_t in_step = 0);

  // Between the substeps of a long step (a block cycle; at 10M particles one can take hours):
  // progress lines, checkpoints when checkpoint.every_seconds have passed, and stop signals heard at
  // once: the first is honoured here with a checkpoint inside the step (a batch system's grace time
  // between its SIGTERM and SIGKILL is far shorter than a cycle); a second before this substep
  // abandons the step unsaved. Every rank comes here at the same substeps, so the signal count and
  // the checkpoint are agreed on collectively.
  void between_substeps(double done, double length);

  const Config& cfg_;
  const RunOptions& opts_;
  std::string dir_;
  Setup setup_;
  Particles<D> p_;
  RunState s_;
  PhaseTimers timers_;
  DistributedDomain<D> domain_{opts_.one_process ? Communicator::self() : Communicator::world(), cfg_.rebalance_threshold};
  RateEvaluator<D> rates_;
  std::unique_ptr<Integrator<D>> integrator_;
  std::vector<double> t_out_;
  SnapshotMeta meta_;
  std::ofstream csv_;
  double trace_origin_us_ = 0;
  Clock::time_point wall_start_ = Clock::now(), last_progress_ = Clock::now(), last_checkpoint_ = Clock::now();
  long long last_checkpoint_step_ = -1;  // -1: none yet
  long long last_output_step_ = -1;      // the step of the last snapshot written (-1: none yet)
  long long substeps_ = 0;               // substeps of this process's run so far (between_substeps)
  RunCounters steps_begin_, steps_end_;     // at the first step of advance() and after its last
  struct {
    double t_begin = 0;         // simulated time at the start of advance()
    std::size_t updates = 0;    // particles given new rates since then (all ranks)
    std::size_t particles = 0;  // at the start of the current step (all ranks)
    std::size_t updates_at_step = 0;  // this rank's rate-evaluation count at the start of the current step
  } advance_;

  // Particles given new rates since the current step began (all ranks; collective).
  std::size_t updates_in_step() const {
    return domain_.comm().sum(std::uint64_t{rates_.particle_updates() - advance_.updates_at_step});
  }
};

}  // namespace sphdisk
