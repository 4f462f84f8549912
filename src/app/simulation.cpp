#include "app/simulation.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "app/diagnostics.hpp"
#include "app/run_directory.hpp"
#include "app/run_setup.hpp"
#include "evaluate/rate_evaluator.hpp"
#include "app/run_identity.hpp"
#include "app/run_log.hpp"
#include "app/run_records.hpp"
#include "app/smoothing_calibration.hpp"
#include "core/error.hpp"
#include "core/large_allocations.hpp"
#include "parallel/timers.hpp"
#include "core/units.hpp"
#include "core/vector_isa.hpp"
#include "domain/distributed_domain.hpp"
#include "integrate/integrator.hpp"
#include "io/atomic_file.hpp"
#include "io/checkpoint.hpp"
#include "io/distributed_output.hpp"
#include "io/snapshot.hpp"
#include "neighbours/cell_grid.hpp"
#include "neighbours/neighbour_lists.hpp"
#include "parallel/loops.hpp"
#include "physics/accretion.hpp"
#include "problems/ring_setup.hpp"

namespace sphdisk {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kDim = 2;  // the ring is 2D (config check rejects others for now)
// Steps between cache-friendly reorderings by cell: orbiting particles drift away from their
// neighbours' places in memory. The schemes that substep gravity take steps 3-20x longer (a block
// cycle is the largest step), so they reorder every step.
long long reorder_interval(const Config& cfg) {
  const Scheme s = scheme_from_name(cfg.scheme);
  return s == Scheme::Respa || s == Scheme::Block ? 1 : 16;
}
// Counts SIGTERM / SIGINT: after the first the run checkpoints and stops when the current step
// ends, or inside a long step (a block cycle) at its next substep; a second one inside such a step
// before then abandons it unsaved (Runner::between_substeps).
volatile std::sig_atomic_t g_stop_signals = 0;
extern "C" void on_stop_signal(int) { g_stop_signals = g_stop_signals + 1; }

// Thrown between the substeps of a step: stopped after a checkpoint inside it (saved), or
// abandoned by a second stop signal (not saved).
struct StepLeft {
  bool saved;
};

// One run from a state (fresh or checkpointed) to the last output time.
class Runner {
 public:
  Runner(const Config& cfg, const RunOptions& opts, std::string dir, Particles<kDim> p, RunState state)
      : cfg_(cfg), opts_(opts), dir_(std::move(dir)), setup_(make_setup(cfg)), p_(std::move(p)), s_(std::move(state)),
        rates_(kernel_from_name(cfg.kernel), s_.smoothing_length, setup_.phys, timers_,
               smoothing_from_name(cfg.smoothing), cfg.neighbours) {
    IntegratorParams ip;
    ip.scheme = scheme_from_name(cfg.scheme);
    ip.tolerance = cfg.tolerance;
    ip.factors = {cfg.orbital_factor, cfg.force_factor, cfg.viscous_factor, cfg.courant_factor, cfg.substep_factor};
    if (cfg.dt_max > 0) ip.dt_max = cfg.dt_max;
    ip.viscous_update = viscous_update_from_name(cfg.resolved_viscous_update());
    ip.max_stages = cfg.max_stages;
    integrator_ = make_integrator<kDim>(ip, rates_);
    p_.set_absent_fields(unused_fields(integrator_->keeps_step_state(), cfg.evolve_energy, setup_.phys.keeps_correction(),
                                         setup_.phys.keeps_correction_shift()));
    integrator_->on_substep([this](double done, double length) { between_substeps(done, length); });
    if (s_.step > 0 || s_.step_state) last_checkpoint_step_ = s_.step;  // resumed from it
    t_out_ = output_times(cfg, setup_);
    meta_.viscosity = setup_.phys.nu;
    meta_.ring_radius = 1.0;
    meta_.disc_mass = setup_.ring.solution.disc_mass;
    meta_.energy = cfg.evolve_energy;
    meta_.units = setup_.units;
    meta_.parameters = cfg.resolved;
    meta_.problem = cfg.initial_conditions.empty() ? "ring" : "initial_conditions";
    meta_.run_id = run_identity(cfg);
    if (distributed()) rates_.set_domain(&domain_);
    rates_.set_pair_storage(pair_storage_from_name(cfg.pair_lists));
    domain_.comm().barrier();  // a common time origin for every rank's trace track
    trace_origin_us_ = par::trace_now_us();
  }

  // A fresh run: rates of the initial state, snapshot_000, first diagnostics row.
  void start() {
    accrete_all();
    if (global_count() == 0) throw UserError("no particles outside the accretion radius: check the initial conditions");
    rebalance();
    integrator_->start(p_);
    check_finite_or_dump();
    while (static_cast<std::size_t>(s_.next_output) < t_out_.size() && t_out_[static_cast<std::size_t>(s_.next_output)] <= s_.time)
      ++s_.next_output;  // outputs before the start are skipped
    write_output(0);
    open_diagnostics();
    diagnostics_row(0.0);
  }

  // A resumed run: the checkpoint holds the rates (acc, du_dt), the integrator state and, where
  // the integrator needs it, the rest of the last evaluation (kRateState). A checkpoint without the
  // latter (written by another scheme, or before sphdisk stored it) is continued with the rates
  // evaluated anew: correct, but not bit for bit the run that wrote it.
  // A checkpoint written inside a block cycle also holds the particles' steps in it (kStepState) and
  // the cycle's state: the first step continues that cycle.
  void restart() {
    rebalance();
    if (s_.step_state) {
      integrator_->resume_inside_step(s_.integrator);
      // The cycle ends where it ends (it was chosen to end at or before the next output then).
      const auto next = static_cast<std::size_t>(s_.next_output);
      const double cycle_end = s_.time + s_.integrator[0];
      if (next < t_out_.size() && t_out_[next] - s_.time < s_.integrator[0])
        throw UserError("the checkpoint was written inside a block cycle that ends at tau " +
                        std::to_string(setup_.tau_of_time(cycle_end)) + ", after the next output time tau " +
                        std::to_string(setup_.tau_of_time(t_out_[next])) +
                        "; resume with output.tau as it was, or with no output before the cycle's end");
    } else {
      integrator_->set_state(s_.integrator);
    }
    if (integrator_->needs_rate_state() && !s_.rate_state) {
      if (root())
        run_log::print(stderr, "sphdisk: note: the checkpoint holds no density and stress of its last evaluation "
                               "(another scheme, or an older sphdisk); they are evaluated anew, so the run continues "
                               "correctly but not bit for bit\n");
      integrator_->start(p_);
    }
    if (root()) truncate_diagnostics(dir_, s_.step);
    open_diagnostics();
  }

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

  // Removes accreted particles; the tallies are added in particle-ID order, so they do not depend
  // on which rank held which particle (a step may accrete several).
  void accrete_all() {
    std::vector<AccretedParticle> all = accrete(p_, setup_.phys.accretion_radius);
    if (distributed()) {
      const auto* mine = reinterpret_cast<const std::byte*>(all.data());
      const auto gathered = domain_.comm().all_gather({mine, mine + all.size() * sizeof(AccretedParticle)});
      all.clear();
      for (const auto& b : gathered) {
        const std::size_t k = all.size();
        all.resize(k + b.size() / sizeof(AccretedParticle));
        if (!b.empty()) std::memcpy(all.data() + k, b.data(), b.size());
      }
    }
    std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
    for (const AccretedParticle& a : all) {
      s_.accreted_mass += a.mass;
      s_.accreted_angular_momentum += a.lz;
    }
  }

  template <class F>
  void on_root(F&& write) {
    run_on_root(domain_.comm(), write);
  }

  void open_diagnostics() {
    if (!root()) return;
    const std::string path = (fs::path(dir_) / kDiagnosticsName).string();
    const bool fresh = !fs::exists(path) || fs::file_size(path) == 0;
    csv_.open(path, std::ios::app);
    if (!csv_) throw UserError("cannot write '" + path + "'");
    if (fresh) csv_ << kDiagnosticsHeader << '\n';
    csv_.precision(17);
  }

  void write_output(std::size_t k) {
    ScopedPhase timer(timers_, "io");
    meta_.time = s_.time;
    meta_.tau = setup_.tau_of_time(s_.time);
    meta_.accreted_mass = s_.accreted_mass;
    meta_.accreted_angular_momentum = s_.accreted_angular_momentum;
    meta_.step = s_.step;
    write_snapshot(domain_.comm(), snapshot_name(dir_, k), p_, meta_);
    last_output_step_ = s_.step;
  }

  // Stops on NaN/Inf, keeping the evidence in a debug dump; the last good checkpoint is untouched.
  void check_finite_or_dump() {
    const std::string bad = find_non_finite(p_, s_.step);
    if (!domain_.any(!bad.empty())) return;
    const std::string dump = (fs::path(dir_) / ("debug_step_" + std::to_string(s_.step) + ".hdf5")).string();
    write_snapshot(domain_.comm(), dump, p_, meta_);
    throw NumericalError((bad.empty() ? "non-finite values on another rank at step " + std::to_string(s_.step) : bad) +
                         "; state written to " + dump +
                         ", last good checkpoint kept; reduce the timestep factors or check the set-up");
  }

  // Between steps, or inside one between its substeps (a block cycle: the particles' steps and the
  // cycle's state go in too; time and step stay those before the cycle).
  void write_checkpoint_now() {
    ScopedPhase timer(timers_, "io");
    s_.step_state = integrator_->inside_step();
    s_.integrator = s_.step_state ? integrator_->step_state() : integrator_->state();
    s_.rate_state = integrator_->needs_rate_state();
    if (root()) csv_.flush();
    write_checkpoint(domain_.comm(), (fs::path(dir_) / kCheckpointName).string(), p_, s_);
    last_checkpoint_ = Clock::now();
    last_checkpoint_step_ = s_.step;
  }

  void diagnostics_row(double dt) {
    ScopedPhase timer(timers_, "diagnostics");
    GlobalSums g = global_sums(p_, cfg_.evolve_energy);
    const std::size_t n = global_count();
    if (distributed()) {
      const Communicator& c = domain_.comm();
      g = GlobalSums{c.sum_in_rank_order(g.mass), c.sum_in_rank_order(g.kinetic_energy),
                     c.sum_in_rank_order(g.internal_energy), c.sum_in_rank_order(g.angular_momentum)};
    }
    if (!root()) return;
    csv_ << s_.step << ',' << s_.time << ',' << setup_.tau_of_time(s_.time) << ',' << dt << ',' << n << ','
         << g.mass << ',' << s_.accreted_mass << ',' << g.kinetic_energy << ',' << g.internal_energy << ','
         << g.angular_momentum << ',' << s_.accreted_angular_momentum << ',' << wall() << '\n';
  }

  RunCounters counters_now() const {
    return {s_.step, rates_.evaluations(), rates_.particle_updates(), rates_.pair_interactions(),
            rates_.smoothing_length_solves(), rates_.smoothing_length_sums(), domain_.traffic()};
  }

  // Per rank: owned particles, ghosts, peak memory and phase timers (load imbalance and
  // communication share per phase; bench/mpi_scaling.sh reads it). Collective; the text on rank 0.
  std::string ranks_json() const {
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    std::ostringstream os;
    os << "{\"rank\": " << domain_.comm().rank() << ", \"particles\": " << p_.size()
       << ", \"ghosts\": " << domain_.halo().ghosts() << ", \"vector_isa\": \"" << vector_isa_name(vector_isa()) << '"'
       << ", \"peak_rss_bytes\": " << ru.ru_maxrss * 1024L
       << ", \"decompositions\": " << domain_.recuts() << ", \"count_imbalance\": " << domain_.imbalance()
       << ", \"rate_evaluations\": " << rates_.evaluations() << ", \"list_builds\": " << rates_.list_builds()
       << ", \"particle_updates\": " << rates_.particle_updates()
       << ", \"pair_interactions\": " << rates_.pair_interactions()
       << ", \"smoothing_length_solves\": " << rates_.smoothing_length_solves()
       << ", \"smoothing_length_sums\": " << rates_.smoothing_length_sums()
       << ", \"involved_evaluations\": " << rates_.involved_evaluations()
       << ", \"involved_widenings\": " << rates_.involved_widenings()
       << ", \"traffic\": " << traffic_json(domain_.traffic())
       << ", \"steps\": " << steps_json(steps_begin_, steps_end_)
       << ", \"memory_bytes\": {\"particles\": " << p_.bytes();
    for (const auto& [part, bytes] : rates_.memory()) os << ", \"" << part << "\": " << bytes;
    os << ", \"integrator\": " << integrator_->bytes();
    os << "}"
       << ", \"timers\": " << timers_.json().substr(0, timers_.json().size() - 1) << "}";
    const std::vector<std::string> all = domain_.comm().gather_to_root(os.str());
    std::string out = "[\n";
    for (std::size_t r = 0; r < all.size(); ++r) out += "  " + all[r] + (r + 1 < all.size() ? ",\n" : "\n");
    return out + "]\n";
  }

  double wall() const { return std::chrono::duration<double>(Clock::now() - wall_start_).count(); }

  // Where the root process's lines go besides run.log: stderr, unless --quiet.
  std::FILE* terminal() const { return opts_.quiet ? nullptr : stderr; }

  // A progress line at most every output.progress_interval seconds: at the end of a step, or
  // inside one (`within`: the fraction of the step's time done, `in_step` the particle updates so
  // far) at simulated time `time`. Into run.log also with --quiet.
  void progress(long long step, double time, double dt, double within = -1, std::size_t in_step = 0) {
    const auto now = Clock::now();
    if (!root() || cfg_.progress_interval <= 0 ||
        std::chrono::duration<double>(now - last_progress_).count() < cfg_.progress_interval)
      return;
    last_progress_ = now;
    const double frac = (time - advance_.t_begin) / (t_out_.back() - advance_.t_begin);
    char inside[64] = "";
    if (within >= 0) std::snprintf(inside, sizeof inside, "  (%.1f%% into the step's block cycle)", 100 * within);
    run_log::print(terminal(), "step %lld  tau %.5f  %5.1f%%  dt %.3e  N %zu  %.3g updates/s  ETA %s%s\n", step,
                   setup_.tau_of_time(time), 100 * frac, dt, advance_.particles,
                   static_cast<double>(advance_.updates + in_step) / wall(),
                   run_log::format_duration(frac > 0 ? wall() * (1 - frac) / frac : 0).c_str(), inside);
  }

  // Between the substeps of a long step (a block cycle; at 10M particles one can take hours):
  // progress lines, checkpoints when checkpoint.every_seconds have passed, and stop signals heard at
  // once: the first is honoured here with a checkpoint inside the step (a batch system's grace time
  // between its SIGTERM and SIGKILL is far shorter than a cycle); a second before this substep
  // abandons the step unsaved. Every rank comes here at the same substeps, so the signal count and
  // the checkpoint are agreed on collectively.
  void between_substeps(double done, double length) {
    ++substeps_;
    if (substeps_ == cfg_.inject_interrupt_at_substep)
      for (long long k = 0; k < cfg_.inject_interrupts; ++k) std::raise(SIGINT);
    if (substeps_ == cfg_.inject_nan_at_substep && p_.size() > 0) p_.acc[0][0] = std::numeric_limits<double>::quiet_NaN();
    const double signals = domain_.comm().max(static_cast<double>(g_stop_signals));
    if (signals >= 2) throw StepLeft{false};
    const bool stop = signals >= 1;
    const bool due = cfg_.checkpoint_every_seconds > 0 &&
                     std::chrono::duration<double>(Clock::now() - last_checkpoint_).count() >= cfg_.checkpoint_every_seconds;
    if (stop || domain_.any(due)) {
      check_finite_or_dump();  // (a checkpoint never holds non-finite values: the last good one stays)
      write_checkpoint_now();
    }
    if (stop) {
      if (root())
        run_log::print(stderr, "sphdisk: stop requested: checkpoint written %.0f%% into the block cycle of step %lld\n",
                       100 * done / length, s_.step + 1);
      throw StepLeft{true};
    }
    const std::size_t in_step = updates_in_step();
    progress(s_.step + 1, s_.time + done, length, done / length, in_step);
  }

  const Config& cfg_;
  const RunOptions& opts_;
  std::string dir_;
  Setup setup_;
  Particles<kDim> p_;
  RunState s_;
  PhaseTimers timers_;
  DistributedDomain<kDim> domain_{opts_.one_process ? Communicator::self() : Communicator::world(), cfg_.rebalance_threshold};
  RateEvaluator<kDim> rates_;
  std::unique_ptr<Integrator<kDim>> integrator_;
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

RunSummary Runner::advance() {
  const long long steps_before = s_.step;
  advance_.t_begin = s_.time;
  advance_.updates = 0;
  const double h = s_.smoothing_length;
  auto old_term = std::signal(SIGTERM, on_stop_signal);
  auto old_int = std::signal(SIGINT, on_stop_signal);
  bool interrupted = false, abandoned = false;
  steps_begin_ = counters_now();
  while (static_cast<std::size_t>(s_.next_output) < t_out_.size() &&
         (cfg_.max_steps == 0 || s_.step - steps_before < cfg_.max_steps)) {
    const std::size_t next = static_cast<std::size_t>(s_.next_output);
    if (s_.step > steps_before) rebalance();
    // (Not when resumed inside a block cycle: its particles are kept in the order of that cycle.)
    if (!integrator_->inside_step() && s_.step % reorder_interval(cfg_) == 0) {
      ScopedPhase timer(timers_, "reorder");
      // Without stored lists (the mode for runs that would not fit), what the evaluations rebuild
      // after a reorder is freed first: otherwise more pages stay with the process and raise its
      // peak (docs/performance.md, "Memory per particle"). Stored lists keep their memory (their
      // peak is elsewhere, and rebuilding them in fresh pages is slower). Of the reorder's grid only
      // the order is kept.
      if (rates_.lean()) rates_.release_rebuilt_memory();
      const std::vector<std::uint32_t> order = std::move(build_cell_grid(p_.pos, p_.id, 2.0 * h).sorted);
      // The copies in parallel (serial, the other threads waited); exact-size copies, not a copy
      // back into each field (par::permute_prefix), which would raise the peak memory.
      p_.gather(order, [](std::size_t n, const auto& f) { par::for_each(n, f, "reorder", 4096); });
    }
    advance_.updates_at_step = rates_.particle_updates();
    advance_.particles = distributed() ? global_count() : p_.size();
    const double dt_cap = t_out_[next] - s_.time;
    const double tau_before = setup_.tau_of_time(s_.time);
    double dt = 0;
    try {
      dt = integrator_->step(p_, dt_cap);
    } catch (const StepLeft& left) {
      // Saved: the checkpoint inside the step holds it. Abandoned: the last checkpoint stays.
      interrupted = true;
      abandoned = !left.saved;
      advance_.updates += updates_in_step();  // (work done, if not kept)
      break;
    }
    advance_.updates += updates_in_step();
    s_.time = dt >= dt_cap ? t_out_[next] : s_.time + dt;
    ++s_.step;
    if (s_.step == cfg_.inject_nan_at_step) p_.vel[0][0] = std::numeric_limits<double>::quiet_NaN();
    accrete_all();
    check_finite_or_dump();
    if (global_count() == 0) throw UserError("all particles were accreted before the last output time");
    diagnostics_row(dt);
    bool checkpoint = false;
    if (s_.time >= t_out_[next]) {
      ++s_.next_output;
      write_output(static_cast<std::size_t>(s_.next_output));
      checkpoint = true;
    }
    if (cfg_.checkpoint_every_steps > 0 && s_.step % cfg_.checkpoint_every_steps == 0) checkpoint = true;
    if (cfg_.checkpoint_every_tau > 0 && std::floor(setup_.tau_of_time(s_.time) / cfg_.checkpoint_every_tau) !=
                                             std::floor(tau_before / cfg_.checkpoint_every_tau))
      checkpoint = true;
    if (cfg_.checkpoint_every_seconds > 0 &&
        std::chrono::duration<double>(Clock::now() - last_checkpoint_).count() >= cfg_.checkpoint_every_seconds)
      checkpoint = true;
    if (domain_.any(g_stop_signals != 0)) checkpoint = interrupted = true;
    checkpoint = domain_.any(checkpoint);  // wall-clock triggers differ between ranks
    if (checkpoint) write_checkpoint_now();
    if (interrupted) break;
    progress(s_.step, s_.time, dt);
  }
  steps_end_ = counters_now();
  std::signal(SIGTERM, old_term);
  std::signal(SIGINT, old_int);
  // Stopped by run.max_steps before the last output: the state then goes into the snapshot of the
  // next output, which `sphdisk resume` replaces when it reaches that output (so the numbering stays
  // that of output.tau), and into a checkpoint to resume from (docs/formats.md, "Run directory").
  const bool stopped_early = !interrupted && static_cast<std::size_t>(s_.next_output) < t_out_.size();
  if (stopped_early && last_output_step_ != s_.step) write_output(static_cast<std::size_t>(s_.next_output) + 1);
  if (stopped_early && last_checkpoint_step_ != s_.step) write_checkpoint_now();
  on_root([&] {
    csv_.close();
    if (!csv_) throw UserError("cannot finish writing diagnostics.csv in '" + dir_ + "' (disk full?)");
  });

  RunSummary sum;
  sum.steps = s_.step - steps_before;
  sum.evaluations = rates_.evaluations();
  sum.particles_final = global_count();
  sum.wall_seconds = wall();
  sum.particle_updates_per_second = static_cast<double>(advance_.updates) / sum.wall_seconds;
  sum.output_dir = dir_;
  sum.interrupted = interrupted;
  sum.stopped_early = stopped_early;
  sum.abandoned = abandoned;
  sum.checkpoint_step = last_checkpoint_step_;
  sum.checkpoint_inside_step = s_.step_state;
  const std::string per_rank = ranks_json();
  std::vector<std::string> traces;  // rank 0: every rank's trace events
  if (!opts_.trace_file.empty())
    traces = domain_.comm().gather_to_root(par::trace_events(domain_.comm().rank(), trace_origin_us_));
  on_root([&] {
    write_text_file(dir_, "timers.json", timers_.json());
    write_text_file(dir_, "ranks.json", per_rank);
    if (!opts_.trace_file.empty() && !par::trace_write(opts_.trace_file, traces))
      throw UserError("cannot write trace file '" + opts_.trace_file + "'");
  });
  if (root()) {  // to the terminal unless --quiet, to run.log always
    run_log::print(terminal(), "phase timers (rank 0 of %d, %d threads, vector loops: %s):\n%s", domain_.comm().size(),
                   par::max_threads(), vector_isa_name(vector_isa()), timers_.table().c_str());
    run_log::print(terminal(),
                   "%s: %lld steps, %zu rate evaluations, %zu particles left, wall %.2f s, %.3g particle-updates/s "
                   "(%.3g per thread over %d rank(s)), %zu rejected steps\n",
                   interrupted ? "interrupted" : "done", sum.steps, sum.evaluations, sum.particles_final, sum.wall_seconds,
                   sum.particle_updates_per_second, sum.particle_updates_per_second / (par::max_threads() * domain_.comm().size()),
                   domain_.comm().size(), integrator_->rejected_steps());
    if (stopped_early)
      run_log::print(terminal(),
                     "stopped by run.max_steps at step %lld, tau %.6g: state in %s and %s; continue with: sphdisk resume %s "
                     "(each resume takes up to run.max_steps steps; --set run.max_steps=0 runs to the end)\n",
                     s_.step, setup_.tau_of_time(s_.time), snapshot_name(dir_, static_cast<std::size_t>(s_.next_output) + 1).c_str(),
                     kCheckpointName, dir_.c_str());
  }
  return sum;
}

void apply_run_options(const Config& cfg, const RunOptions& opts) {
  par::set_threads(cfg.threads);
  limit_vector_isa(vector_isa_limit_from_name(cfg.vector_isa));
  if (!opts.trace_file.empty()) par::trace_enable(true);
  g_stop_signals = 0;
}

}  // namespace

// More threads than the CPUs this process is bound to, on a machine that has more (an MPI launcher
// binds up to two ranks to one core each by default): the threads take turns; say so once, with the fix.
void warn_if_threads_share_cpus(const Communicator& comm, const RunOptions& opts) {
  const int threads = par::max_threads(), cpus = par::cpus_available();
  const long online = sysconf(_SC_NPROCESSORS_ONLN);  // more threads than the machine's cores is the user's choice
  if (opts.quiet || !comm.is_root() || threads <= cpus || cpus >= online) return;
  run_log::print(stderr,
                 "sphdisk: warning: %d threads but this process may run on %d CPU(s), so threads will take turns; "
                 "with mpirun, give each rank its cores: --map-by slot:PE=%d (or use fewer threads)\n",
                 threads, cpus, threads);
}

// The global h giving `neighbours` neighbours on average over all ranks' particles. Over ranks the
// particles are first sent to their owners (compact regions, few ghosts); the decomposition's
// lattice only groups particles, so its smallest cell size is immaterial (make_lattice widens it).
double calibrated_smoothing_length(const Communicator& comm, Particles<kDim>& p, double neighbours) {
  if (comm.size() == 1) return calibrate_smoothing_length(p, neighbours);
  DistributedDomain<kDim> domain(comm);
  domain.rebalance(p, std::numeric_limits<double>::min());
  return calibrate_smoothing_length<kDim>(p, neighbours, &domain);
}

std::string interruption_note(const RunSummary& s) {
  if (!s.abandoned) return "interrupted by a signal; checkpoint written; continue with: sphdisk resume " + s.output_dir;
  if (s.checkpoint_step < 0)
    return "stopped by a second signal inside a block cycle, before the run wrote any checkpoint; start the run "
           "again with sphdisk run";
  return "stopped by a second signal inside a block cycle, which was not saved; continue from the checkpoint of step " +
         std::to_string(s.checkpoint_step) + (s.checkpoint_inside_step ? " (inside the next cycle)" : "") +
         " with: sphdisk resume " + s.output_dir;
}

RunSummary run_simulation(const Config& cfg, const RunOptions& opts) {
  apply_run_options(cfg, opts);
  const std::string dir = opts.output_dir.empty() ? cfg.output_dir : opts.output_dir;
  const Setup setup = make_setup(cfg);
  check_memory(static_cast<std::size_t>(cfg.particles), cfg.neighbours, smoothing_from_name(cfg.smoothing) == Smoothing::Adaptive);
  // Runs without stored lists are those that would not fit otherwise: from the first array on,
  // large ones go back to the system when freed (stored lists keep theirs, and fresh pages would
  // cost them page faults).
  if (pair_storage_from_name(cfg.pair_lists) == PairStorage::Rescan) map_large_allocations(std::size_t{1} << 20);

  const Communicator comm = opts.one_process ? Communicator::self() : Communicator::world();
  Particles<kDim> p;
  RunState state;
  if (!cfg.initial_conditions.empty()) {
    if (!fs::exists(cfg.initial_conditions))
      throw UserError("problem.initial_conditions: no file '" + cfg.initial_conditions +
                      "' (a relative path is taken from the configuration file's directory, or with --set from the "
                      "current directory)");
    // Each rank reads 1/P of the file's rows; the decomposition then sends each to its owner.
    SnapshotMeta meta;
    const h5::RowShare share{static_cast<std::size_t>(comm.rank()), static_cast<std::size_t>(comm.size())};
    run_collectively(comm, [&] { p = read_snapshot<kDim>(cfg.initial_conditions, &setup.units, meta, share); });
    if (!ids_unique(comm, p.id)) throw UserError("'" + cfg.initial_conditions + "': ParticleIDs are not unique");
    state.time = meta.time;
    state.accreted_mass = meta.accreted_mass;
    state.accreted_angular_momentum = meta.accreted_angular_momentum;
  } else {
    p = make_ring(setup.ring, static_cast<std::size_t>(comm.rank()), static_cast<std::size_t>(comm.size()));
    state.time = setup.time_of_tau(cfg.tau_start);
  }
  if (output_times(cfg, setup).back() <= state.time)
    throw UserError("every output time is at or before the initial time (t = " + std::to_string(state.time) + ", tau = " +
                    std::to_string(setup.tau_of_time(state.time)) + "); give output times after it");
  // h: given, or from the target mean neighbour number (analytically for the ring, measured on
  // the particles for a user's file). Constant smoothing keeps it for all particles and times
  // (P98 sec. 5.3); adaptive smoothing starts its per-particle solve from it.
  state.smoothing_length = cfg.smoothing_length > 0         ? cfg.smoothing_length
                           : cfg.initial_conditions.empty() ? ring_smoothing_length(setup.ring, cfg.neighbours)
                                                            : calibrated_smoothing_length(comm, p, cfg.neighbours);
  for (auto& hi : p.h) hi = state.smoothing_length;
  state.config_toml = cfg.resolved_toml;

  // Inputs are valid: only now touch the output directory.
  run_on_root(comm, [&] {
    prepare_output_dir(dir, opts.overwrite);
    if (opts.overwrite) remove_earlier_run(dir);
    write_text_file(dir, "config.toml", cfg.resolved_toml);
    run_log::open(dir);
    run_log::write(run_log::header("run", opts.command_line, comm.size(), par::max_threads()));
  });
  warn_if_threads_share_cpus(comm, opts);
  Runner runner(cfg, opts, dir, std::move(p), std::move(state));
  runner.start();
  return runner.advance();
}

RunSummary resume_simulation(const std::string& dir, const RunOptions& opts, const std::vector<std::string>& overrides) {
  const std::string path = (fs::path(dir) / kCheckpointName).string();
  if (!fs::exists(path))
    throw UserError("no checkpoint in '" + dir + "' (expected " + kCheckpointName + "); start the run again with sphdisk run");
  RunState state;
  const Communicator comm = opts.one_process ? Communicator::self() : Communicator::world();
  Particles<kDim> p = read_checkpoint(path, state, comm);
  // A checkpoint records every key; one written before a key existed, or before its default
  // changed, continues with what it ran then (unless the user overrides it): eq. 6's conservative
  // form, the summed densities' ratio, and the leapfrog on stored lists.
  std::vector<std::string> all_overrides = overrides;
  for (const auto& [key, earlier] : {std::pair{"viscous_force", "sph.viscous_force=\"conservative\""},
                                     std::pair{"pair_density", "sph.pair_density=\"summation\""},
                                     std::pair{"scheme", "integrator.scheme=\"leapfrog\""},
                                     std::pair{"pair_lists", "sph.pair_lists=\"stored\""},
                                     std::pair{"viscous_update", "integrator.viscous_update=\"explicit\""}})
    if (state.config_toml.find(key) == std::string::npos) all_overrides.insert(all_overrides.begin(), earlier);
  const Config cfg = parse_config(state.config_toml, path, all_overrides);
  // Later checkpoints record what this run continues with, overrides included, so that a second
  // resume keeps them.
  state.config_toml = cfg.resolved_toml;
  apply_run_options(cfg, opts);
  run_on_root(comm, [&] {
    char what[96];
    std::snprintf(what, sizeof what, "resume from step %lld (tau %.6g)", state.step,
                  make_setup(cfg).tau_of_time(state.time));
    run_log::open(dir);
    run_log::write(run_log::header(what, opts.command_line, comm.size(), par::max_threads()));
  });
  warn_if_threads_share_cpus(comm, opts);
  Runner runner(cfg, opts, dir, std::move(p), std::move(state));
  runner.restart();
  return runner.advance();
}

}  // namespace sphdisk
