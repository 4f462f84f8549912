#include "app/simulation.hpp"

#include <unistd.h>

#include <filesystem>
#include <limits>

#include "app/run_directory.hpp"
#include "app/run_identity.hpp"
#include "app/run_log.hpp"
#include "app/run_setup.hpp"
#include "app/runner.hpp"
#include "app/smoothing_calibration.hpp"
#include "core/error.hpp"
#include "core/large_allocations.hpp"
#include "io/checkpoint.hpp"
#include "io/distributed_output.hpp"
#include "io/snapshot.hpp"
#include "parallel/loops.hpp"
#include "parallel/order_free_sum.hpp"
#include "problems/ring_setup.hpp"

namespace sphdisk {

namespace fs = std::filesystem;

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
template <int D>
double calibrated_smoothing_length(const Communicator& comm, Particles<D>& p, double neighbours) {
  if (comm.size() == 1) return calibrate_smoothing_length(p, neighbours);
  DistributedDomain<D> domain(comm);
  domain.rebalance(p, std::numeric_limits<double>::min());
  return calibrate_smoothing_length<D>(p, neighbours, &domain);
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

namespace {

// A fresh run in D dimensions (sph.dimension), from the ring set-up or a user's file.
template <int D>
RunSummary run_in(Config cfg, const RunOptions& opts, const std::string& dir, const Setup& setup) {
  const Communicator comm = opts.one_process ? Communicator::self() : Communicator::world();
  Particles<D> p;
  RunState state;
  if (!cfg.initial_conditions.empty()) {
    check_initial_conditions_file(cfg);
    // A file of another dimension would put a 2D disc in one plane of a 3D run, or drop a 3D
    // disc's heights; other codes' files record none and are read as they are.
    int recorded = 0;
    run_collectively(comm, [&] { recorded = snapshot_dimension(cfg.initial_conditions, 0); });
    if (recorded != 0 && recorded != D)
      throw UserError("problem.initial_conditions '" + cfg.initial_conditions + "' holds a " + std::to_string(recorded) +
                      "D run (Header/SimulationDimension) but sph.dimension = " + std::to_string(D) + "; set sph.dimension = " +
                      std::to_string(recorded));
    // Each rank reads 1/P of the file's rows; the decomposition then sends each to its owner.
    SnapshotMeta meta;
    const h5::RowShare share{static_cast<std::size_t>(comm.rank()), static_cast<std::size_t>(comm.size())};
    run_collectively(comm, [&] { p = read_snapshot<D>(cfg.initial_conditions, &setup.units, meta, share); });
    if (!ids_unique(comm, p.id)) throw UserError("'" + cfg.initial_conditions + "': ParticleIDs are not unique");
    state.time = meta.time;
    state.accreted_mass = meta.accreted_mass;
    state.accreted_angular_momentum = meta.accreted_angular_momentum;
    state.initial_mass = order_free_sum(comm, p.mass) + meta.accreted_mass;
    cfg = with_neighbours_resolved(cfg, comm.sum_in_rank_order(static_cast<double>(p.size())));
  } else {
    const auto share = static_cast<std::size_t>(comm.rank()), shares = static_cast<std::size_t>(comm.size());
    p = setup.sedov  ? make_sedov_blast<D>(setup.sedov_blast, share, shares)
        : setup.disc ? sample_disc<D>(setup.disc_sampling, share, shares)
                     : make_ring<D>(setup.ring, share, shares);
    // The ring starts at its viscous time, the others at t = 0.
    state.time = setup.disc || setup.sedov ? 0.0 : setup.time_of_tau(cfg.tau_start);
  }
  if (output_times(cfg, setup).back() <= state.time)
    throw UserError("every output time is at or before the initial time (t = " + std::to_string(state.time) + ", tau = " +
                    std::to_string(setup.tau_of_time(state.time)) + "); give output times after it");
  // h: given, or from the target mean neighbour number (analytically for the 2D ring, measured on
  // the particles otherwise). Constant smoothing keeps it for all particles and times (P98 sec.
  // 5.3); adaptive smoothing starts its per-particle solve from it.
  const bool ring = cfg.initial_conditions.empty() && !setup.disc && !setup.sedov;
  state.smoothing_length = cfg.smoothing_length > 0 ? cfg.smoothing_length
                           : ring && D == 2         ? ring_smoothing_length(setup.ring, cfg.neighbours)
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
  Runner<D> runner(cfg, opts, dir, std::move(p), std::move(state));
  runner.start();
  return runner.advance();
}

}  // namespace

void check_initial_conditions_file(const Config& cfg) {
  if (!cfg.initial_conditions.empty() && !fs::is_regular_file(cfg.initial_conditions))
    throw UserError("problem.initial_conditions: no file '" + cfg.initial_conditions +
                    "' (a relative path is taken from the configuration file's directory, or with --set from the "
                    "current directory)");
}

RunSummary run_simulation(const Config& given_cfg, const RunOptions& opts) {
  // A generated problem has its N now; a user's file resolves "auto" once it is read (run_in).
  const Config cfg = given_cfg.initial_conditions.empty()
                         ? with_neighbours_resolved(given_cfg, static_cast<double>(given_cfg.particles))
                         : given_cfg;
  check_neighbours_fit(cfg);
  apply_run_options(cfg, opts);
  const std::string dir = opts.output_dir.empty() ? cfg.output_dir : opts.output_dir;
  const Setup setup = make_setup(cfg);
  check_memory(static_cast<std::size_t>(cfg.particles),
               cfg.neighbours_auto() ? auto_neighbours(cfg.dimension, static_cast<double>(cfg.particles)) : cfg.neighbours,
               smoothing_from_name(cfg.smoothing) == Smoothing::Adaptive);
  // Runs without stored lists are those that would not fit otherwise: from the first array on,
  // large ones go back to the system when freed (stored lists keep theirs, and fresh pages would
  // cost them page faults).
  if (pair_storage_from_name(cfg.pair_lists) == PairStorage::Rescan) map_large_allocations(std::size_t{1} << 20);

  return cfg.dimension == 3 ? run_in<3>(cfg, opts, dir, setup) : run_in<2>(cfg, opts, dir, setup);
}

namespace {

// The settings a resume may not change: the problem.* settings made the particles that the
// checkpoint holds (their number, masses, units and time origin), the central mass sets the code
// units their state is in, the viscosity the clock that maps time to tau, and a run continues in
// its own directory (output.dir). setting: a key, or an override "key=value".
bool fixed_on_resume(const std::string& setting) {
  std::string key = setting.substr(0, setting.find('='));
  key.erase(key.find_last_not_of(" \t") + 1);
  key.erase(0, key.find_first_not_of(" \t"));
  return key.rfind("problem.", 0) == 0 || key == "physics.central_mass" || key == "physics.viscosity" || key == "output.dir";
}

// A resume that changes one is refused, as the run could not honour it.
void refuse_changed_problem(const Config& stored, const Config& cfg, const std::string& dir) {
  for (std::size_t k = 0; k < cfg.resolved.size() && k < stored.resolved.size(); ++k) {
    const auto& [key, value] = cfg.resolved[k];
    if (!fixed_on_resume(key) || value == stored.resolved[k].second) continue;
    if (key == "output.dir")
      throw UserError("output.dir cannot change on resume: a run continues in its own directory ('" + dir +
                      "'); copy the directory and resume the copy to continue elsewhere");
    const std::string why = key.rfind("problem.", 0) == 0 ? "the checkpoint's particles were made with "
                                                           : "the run's code units and its clock of tau were set by ";
    throw UserError(key + " cannot change on resume (" + why + key + " = " + stored.resolved[k].second +
                    "); start a new run with sphdisk run");
  }
}

template <int D>
RunSummary resume_in(const std::string& path, const std::string& dir, const RunOptions& opts,
                     const std::vector<std::string>& overrides) {
  RunState state;
  const Communicator comm = opts.one_process ? Communicator::self() : Communicator::world();
  Particles<D> p = read_checkpoint<D>(path, state, comm);
  // A checkpoint records every key; one written before a key existed, or before its default
  // changed, continues with what it ran then (unless the user overrides it): eq. 6's conservative
  // form, the summed densities' ratio, and the leapfrog on stored lists.
  std::vector<std::string> earlier_defaults;
  for (const auto& [key, earlier] : {std::pair{"viscous_force", "sph.viscous_force=\"conservative\""},
                                     std::pair{"pair_density", "sph.pair_density=\"summation\""},
                                     std::pair{"av_switch", "physics.av_switch=\"none\""},
                                     std::pair{"scheme", "integrator.scheme=\"leapfrog\""},
                                     std::pair{"pair_lists", "sph.pair_lists=\"stored\""},
                                     std::pair{"viscous_update", "integrator.viscous_update=\"explicit\""}})
    if (state.config_toml.find(key) == std::string::npos) earlier_defaults.emplace_back(earlier);
  std::vector<std::string> all_overrides = earlier_defaults;
  all_overrides.insert(all_overrides.end(), overrides.begin(), overrides.end());
  // "auto" neighbours given on resume: from the particles the run has now.
  // What the checkpoint's particles were made with: its settings fixed on resume, the user's
  // overrides of the others (which may replace a retired value the stored configuration names).
  std::vector<std::string> other_overrides = earlier_defaults;
  for (const std::string& o : overrides)
    if (!fixed_on_resume(o)) other_overrides.push_back(o);
  const double particles = comm.sum_in_rank_order(static_cast<double>(p.size()));
  const Config stored = with_neighbours_resolved(parse_config(state.config_toml, path, other_overrides), particles);
  const Config cfg = with_neighbours_resolved(parse_config(state.config_toml, path, all_overrides), particles);
  if (cfg.dimension != D)
    throw UserError("the checkpoint in '" + dir + "' holds a " + std::to_string(D) + "D run; sph.dimension cannot change on resume");
  refuse_changed_problem(stored, cfg, dir);
  const Setup setup = make_setup(cfg);
  if (state.next_output >= static_cast<long long>(output_times(cfg, setup).size()))
    throw UserError("the run in '" + dir + "' is complete (every output written); to go on, resume it with later output "
                    "times, e.g. --set 'output.tau=[0.09, 0.2]' (or output.times, output.orbits, as the run gives them)");
  // A checkpoint from before format 11 names no identity: its run's is the one its first snapshot
  // records, or without that snapshot that of its settings.
  if (state.run_id.empty()) {
    const std::string first = snapshot_name(dir, 0);
    if (fs::exists(first)) state.run_id = snapshot_run_id(first);
    if (state.run_id.empty()) state.run_id = run_identity(stored);
  }
  // Later checkpoints record what this run continues with, overrides included, so that a second
  // resume keeps them.
  state.config_toml = cfg.resolved_toml;
  apply_run_options(cfg, opts);
  run_on_root(comm, [&] {
    char what[96];
    std::snprintf(what, sizeof what, "resume from step %lld (tau %.6g)", state.step,
                  setup.tau_of_time(state.time));
    run_log::open(dir);
    run_log::write(run_log::header(what, opts.command_line, comm.size(), par::max_threads()));
  });
  warn_if_threads_share_cpus(comm, opts);
  Runner<D> runner(cfg, opts, dir, std::move(p), std::move(state));
  runner.restart();
  return runner.advance();
}

}  // namespace

RunSummary resume_simulation(const std::string& dir, const RunOptions& opts, const std::vector<std::string>& overrides) {
  const std::string path = (fs::path(dir) / kCheckpointName).string();
  if (!fs::exists(path))
    throw UserError("no checkpoint in '" + dir + "' (expected " + kCheckpointName + "); start the run again with sphdisk run");
  return checkpoint_dimension(path) == 3 ? resume_in<3>(path, dir, opts, overrides) : resume_in<2>(path, dir, opts, overrides);
}

}  // namespace sphdisk
