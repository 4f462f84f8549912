#include "app/runner.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <sstream>

#include "app/diagnostics.hpp"
#include "app/run_directory.hpp"
#include "app/run_identity.hpp"
#include "app/run_log.hpp"
#include "core/error.hpp"
#include "core/vector_isa.hpp"
#include "io/distributed_output.hpp"
#include "neighbours/cell_grid.hpp"
#include "parallel/loops.hpp"
#include "parallel/trace.hpp"
#include "physics/accretion.hpp"

namespace sphdisk {

namespace fs = std::filesystem;

namespace {

// Steps between cache-friendly reorderings by cell: orbiting particles drift away from their
// neighbours' places in memory. The schemes that substep gravity take steps 3-20x longer (a block
// cycle is the largest step), so they reorder every step.
long long reorder_interval(const Config& cfg) {
  const Scheme s = scheme_from_name(cfg.scheme);
  return s == Scheme::Respa || s == Scheme::Block ? 1 : 16;
}
// Counts SIGTERM / SIGINT: after the first the run checkpoints and stops when the current step
// ends, or inside a long step (a block cycle) at its next substep; a second one inside such a step
// before then abandons it unsaved (Runner<D>::between_substeps).
volatile std::sig_atomic_t g_stop_signals = 0;
extern "C" void on_stop_signal(int) { g_stop_signals = g_stop_signals + 1; }

// Thrown between the substeps of a step: stopped after a checkpoint inside it (saved), or
// abandoned by a second stop signal (not saved).
struct StepLeft {
  bool saved;
};

}  // namespace

template <int D>
Runner<D>::Runner(const Config& cfg, const RunOptions& opts, std::string dir, Particles<D> p, RunState state)
    : cfg_(cfg), opts_(opts), dir_(std::move(dir)), setup_(make_setup(cfg)), p_(std::move(p)), s_(std::move(state)),
      rates_(kernel_from_name(cfg.kernel), s_.smoothing_length, setup_.phys, timers_, smoothing_from_name(cfg.smoothing),
             cfg.neighbours) {
  IntegratorParams ip;
  ip.scheme = scheme_from_name(cfg.scheme);
  ip.tolerance = cfg.tolerance;
  ip.factors = {cfg.orbital_factor, cfg.force_factor, cfg.viscous_factor, cfg.courant_factor, cfg.substep_factor};
  if (cfg.dt_max > 0) ip.dt_max = cfg.dt_max;
  ip.viscous_update = viscous_update_from_name(cfg.resolved_viscous_update());
  ip.max_stages = cfg.max_stages;
  integrator_ = make_integrator<D>(ip, rates_);
  p_.set_absent_fields(unused_fields(integrator_->keeps_step_state(), cfg.evolve_energy, setup_.phys.keeps_correction(),
                                       setup_.phys.keeps_correction_shift(), setup_.phys.artificial_viscosity(),
                                       setup_.phys.keeps_scatter_density()));
  integrator_->on_substep([this](double done, double length) { between_substeps(done, length); });
  if (s_.step > 0 || s_.step_state) last_checkpoint_step_ = s_.step;  // resumed from it
  t_out_ = output_times(cfg, setup_);
  meta_.viscosity = setup_.phys.nu;
  meta_.ring_radius = 1.0;
  // The blast wave's cube has mass 1; a run from a file, the mass its particles started with.
  meta_.disc_mass = setup_.sedov ? 1.0 : s_.initial_mass > 0 ? s_.initial_mass : setup_.ring.solution.disc_mass;
  meta_.energy = cfg.evolve_energy;
  meta_.units = setup_.units;
  meta_.parameters = cfg.resolved;
  meta_.problem = !cfg.initial_conditions.empty() ? "initial_conditions" : setup_.problem_name();
  if (s_.run_id.empty()) s_.run_id = run_identity(cfg);  // a resumed run keeps the identity it started with
  meta_.run_id = s_.run_id;
  if (distributed()) rates_.set_domain(&domain_);
  rates_.set_pair_storage(pair_storage_from_name(cfg.pair_lists));
  domain_.comm().barrier();  // a common time origin for every rank's trace track
  trace_origin_us_ = par::trace_now_us();
}

template <int D>
void Runner<D>::start() {
  // Every particle's artificial viscosity starts at its least alpha (the switch raises it where the
  // flow converges), or at the one alpha without the switch.
  if (setup_.phys.artificial_viscosity())
    std::fill(p_.av_alpha.begin(), p_.av_alpha.end(), setup_.phys.av_switch ? setup_.phys.av_alpha_min : setup_.phys.av_alpha);
  accrete_all();
  if (global_count() == 0) throw UserError("no particles outside the accretion radius: check the initial conditions");
  rebalance();
  integrator_->start(p_);
  warn_if_vertically_unresolved();
  check_finite_or_dump();
  while (static_cast<std::size_t>(s_.next_output) < t_out_.size() && t_out_[static_cast<std::size_t>(s_.next_output)] <= s_.time)
    ++s_.next_output;  // outputs before the start are skipped
  write_output(0);
  open_diagnostics();
  diagnostics_row(0.0);
}

template <int D>
void Runner<D>::restart() {
  // With the switch each particle's alpha is its own and checkpointed; without it, the one alpha.
  if (setup_.phys.artificial_viscosity() && !setup_.phys.av_switch) std::fill(p_.av_alpha.begin(), p_.av_alpha.end(), setup_.phys.av_alpha);
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

template <int D>
void Runner<D>::warn_if_vertically_unresolved() {
  const PhysicsParams& phys = setup_.phys;
  if (D != 3 || (phys.eos != EquationOfState::Isothermal && phys.eos != EquationOfState::LocallyIsothermal)) return;
  std::uint64_t taller = 0;
  for (std::size_t i = 0; i < p_.size(); ++i)
    if (p_.h[i] > scale_height_at(phys, p_.pos[i])) ++taller;
  taller = domain_.comm().sum(taller);
  const std::uint64_t all = global_count();
  if (root() && 2 * taller > all)
    run_log::print(stderr,
                   "sphdisk: warning: the kernels are taller than the disc: h > H = c_s / Omega for %.0f%% of the "
                   "particles, so its vertical structure is unresolved and its viscous spreading rate not converged "
                   "(it is from h/H ~ 0.5 on); raise problem.particles (h ~ N^-1/3) or the sound speed "
                   "(docs/validation.md, \"The rate a ring with pressure should have\")\n",
                   100.0 * static_cast<double>(taller) / static_cast<double>(all));
}

template <int D>
void Runner<D>::accrete_all() {
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

template <int D>
void Runner<D>::open_diagnostics() {
  if (!root()) return;
  const std::string path = (fs::path(dir_) / kDiagnosticsName).string();
  const bool fresh = !fs::exists(path) || fs::file_size(path) == 0;
  csv_.open(path, std::ios::app);
  if (!csv_) throw UserError("cannot write '" + path + "': " + std::strerror(errno) + "; check the output directory's permissions and free space");
  if (fresh) csv_ << kDiagnosticsHeader << '\n';
  csv_.precision(17);
}

template <int D>
void Runner<D>::write_output(std::size_t k) {
  ScopedPhase timer(timers_, "io");
  meta_.time = s_.time;
  meta_.tau = setup_.tau_of_time(s_.time);
  meta_.accreted_mass = s_.accreted_mass;
  meta_.accreted_angular_momentum = s_.accreted_angular_momentum;
  meta_.step = s_.step;
  write_snapshot(domain_.comm(), snapshot_name(dir_, k), p_, meta_);
  last_output_step_ = s_.step;
}

template <int D>
void Runner<D>::check_finite_or_dump() {
  const std::string bad = find_non_finite(p_, s_.step);
  if (!domain_.any(!bad.empty())) return;
  const std::string dump = (fs::path(dir_) / ("debug_step_" + std::to_string(s_.step) + ".hdf5")).string();
  write_snapshot(domain_.comm(), dump, p_, meta_);
  throw NumericalError((bad.empty() ? "non-finite values on another rank at step " + std::to_string(s_.step) : bad) +
                       "; state written to " + dump +
                       (fs::exists(fs::path(dir_) / kCheckpointName) ? ", last good checkpoint kept" : ", no checkpoint written yet") +
                       "; reduce the timestep factors or check the set-up");
}

template <int D>
void Runner<D>::write_checkpoint_now() {
  ScopedPhase timer(timers_, "io");
  s_.step_state = integrator_->inside_step();
  s_.integrator = s_.step_state ? integrator_->step_state() : integrator_->state();
  s_.rate_state = integrator_->needs_rate_state();
  if (root()) csv_.flush();
  write_checkpoint(domain_.comm(), (fs::path(dir_) / kCheckpointName).string(), p_, s_);
  last_checkpoint_ = Clock::now();
  last_checkpoint_step_ = s_.step;
}

template <int D>
void Runner<D>::diagnostics_row(double dt) {
  ScopedPhase timer(timers_, "diagnostics");
  const GlobalSums g = global_sums(domain_.comm(), p_, cfg_.evolve_energy);
  const std::size_t n = global_count();
  if (!root()) return;
  csv_ << s_.step << ',' << s_.time << ',' << setup_.tau_of_time(s_.time) << ',' << dt << ',' << n << ','
       << g.mass << ',' << s_.accreted_mass << ',' << g.kinetic_energy << ',' << g.internal_energy << ','
       << g.angular_momentum << ',' << s_.accreted_angular_momentum << ',' << wall() << '\n';
}

template <int D>
std::string Runner<D>::ranks_json() const {
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
     << ", \"halo_widenings\": " << rates_.halo_widenings()
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

template <int D>
void Runner<D>::progress(long long step, double time, double dt, double within, std::size_t in_step) {
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

template <int D>
void Runner<D>::between_substeps(double done, double length) {
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

template <int D>
RunSummary Runner<D>::advance() {
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
      // Each field rearranged in place through one scratch of the widest field's size (on huge
      // pages): no field is allocated, zero-filled and faulted in afresh on the main thread alone.
      std::size_t widest = 0;
      p_.for_each_field([&widest](const FieldInfo&, const auto& v) { widest = std::max(widest, sizeof(v[0])); });
      UnsetVector<std::byte> scratch(order.size() * widest);
      p_.for_each_field([&](const FieldInfo&, auto& v) { par::permute_prefix(v, order, scratch, "reorder"); });
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
  // The stopped state's snapshot: the next output's, unless the stop fell on an output time, whose
  // snapshot (the last written) holds it already.
  const bool at_output = last_output_step_ == s_.step;
  const std::size_t state_snapshot = static_cast<std::size_t>(s_.next_output) + (at_output ? 0 : 1);
  if (stopped_early && !at_output) write_output(state_snapshot);
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
    if (stopped_early)  // (with --quiet too: the run is not finished)
      run_log::print(stderr,
                     "stopped by run.max_steps at step %lld, tau %.6g: state in %s and %s; continue with: sphdisk resume %s "
                     "(each resume takes up to run.max_steps steps; --set run.max_steps=0 runs to the end)\n",
                     s_.step, setup_.tau_of_time(s_.time), snapshot_name(dir_, state_snapshot).c_str(),
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


template class Runner<2>;
template class Runner<3>;

}  // namespace sphdisk
