#include "app/simulation.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "app/diagnostics.hpp"
#include "app/rate_evaluator.hpp"
#include "core/error.hpp"
#include "core/timers.hpp"
#include "core/units.hpp"
#include "integrate/integrator.hpp"
#include "io/snapshot.hpp"
#include "neighbours/cell_grid.hpp"
#include "neighbours/neighbour_lists.hpp"
#include "parallel/loops.hpp"
#include "problems/ring_setup.hpp"

namespace sphdisk {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kDim = 2;  // the ring is 2D (config check rejects others for now)
constexpr long long kReorderInterval = 16;  // steps between cache-friendly reorderings by cell

std::string snapshot_name(const std::string& dir, std::size_t k) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "snapshot_%03zu.hdf5", k);
  return (fs::path(dir) / buf).string();
}

// Refuses to replace results of an earlier run unless asked; checks the directory is writable.
void prepare_output_dir(const std::string& dir, bool overwrite) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw UserError("cannot create output directory '" + dir + "': " + ec.message() + "; choose another with --output");
  if (!overwrite) {
    for (const auto& e : fs::directory_iterator(dir)) {
      const std::string name = e.path().filename().string();
      if (name.rfind("snapshot_", 0) == 0 || name == "diagnostics.csv")
        throw UserError("output directory '" + dir + "' already holds results (" + name +
                        "); use --output for a new directory or --overwrite to replace them");
    }
  }
  const std::string probe = (fs::path(dir) / ".sphdisk_write_test").string();
  std::ofstream f(probe);
  if (!f || !(f << "x") || (f.close(), !f)) throw UserError("output directory '" + dir + "' is not writable; choose another with --output");
  fs::remove(probe, ec);
}

// Writes text to dir/name atomically (temporary file, fsync, rename).
void write_text_file(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string final_path = (fs::path(dir) / name).string(), tmp = final_path + ".tmp";
  {
    std::ofstream f(tmp);
    f << text;
    if (!f.flush()) throw UserError("cannot write '" + tmp + "' (disk full?)");
  }
  publish_file(tmp, final_path);
}

std::string format_duration(double s) {
  char buf[32];
  if (s < 60) std::snprintf(buf, sizeof buf, "%.0fs", s);
  else if (s < 3600) std::snprintf(buf, sizeof buf, "%dm%02ds", int(s / 60), int(s) % 60);
  else std::snprintf(buf, sizeof buf, "%dh%02dm", int(s / 3600), int(s / 60) % 60);
  return buf;
}

// Stops the run on the first non-finite value, naming particle, field and step.
template <int D>
void check_finite(const Particles<D>& p, long long step) {
  const std::size_t bad = par::reduce(
      p.size(), p.size(),
      [&](std::size_t i) {
        bool ok = std::isfinite(p.u[i]);
        for (int k = 0; k < D; ++k) ok = ok && std::isfinite(p.pos[i][k]) && std::isfinite(p.vel[i][k]) && std::isfinite(p.acc[i][k]);
        return ok ? p.size() : i;
      },
      [](std::size_t a, std::size_t b) { return std::min(a, b); });
  if (bad == p.size()) return;
  const char* field = "internal energy";
  for (int k = 0; k < D; ++k) {
    if (!std::isfinite(p.acc[bad][k])) field = "acceleration";
    if (!std::isfinite(p.vel[bad][k])) field = "velocity";
    if (!std::isfinite(p.pos[bad][k])) field = "position";
  }
  throw NumericalError("non-finite " + std::string(field) + " of particle ID " + std::to_string(p.id[bad]) +
                       " at step " + std::to_string(step) + "; reduce the timestep factors or check the set-up");
}

// Removes particles inside the accretion radius; their mass and L_z go to the central object.
template <int D>
void accrete(Particles<D>& p, double r_acc, double& accreted_mass, double& accreted_lz) {
  if (r_acc <= 0) return;
  const double r2 = r_acc * r_acc;
  std::vector<std::uint32_t> keep;
  keep.reserve(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (norm2(p.pos[i]) < r2) {
      accreted_mass += p.mass[i];
      accreted_lz += p.mass[i] * angular_momentum_z(p.pos[i], p.vel[i]);
    } else {
      keep.push_back(static_cast<std::uint32_t>(i));
    }
  }
  if (keep.size() != p.size()) p.gather(keep);
}

}  // namespace

RunSummary run_simulation(const Config& cfg, const RunOptions& opts) {
  const auto wall_start = Clock::now();
  par::set_threads(cfg.threads);
  if (!opts.trace_file.empty()) par::trace_enable(true);
  const std::string dir = opts.output_dir.empty() ? cfg.output_dir : opts.output_dir;

  // Code units: length r0, mass M, G = 1 (core/units.hpp).
  const UnitSystem units = UnitSystem::from_solar(cfg.ring_radius, cfg.central_mass);
  const double rsun2_per_s = cgs::solar_radius * cgs::solar_radius * units.time_s / (units.length_cm * units.length_cm);
  PhysicsParams phys;
  phys.gm = 1.0;
  phys.nu = cfg.viscosity * rsun2_per_s;
  phys.nu_bulk = cfg.bulk_viscosity * rsun2_per_s;
  phys.eos = cfg.eos == "isothermal" ? EquationOfState::Isothermal : EquationOfState::None;
  phys.sound_speed = cfg.sound_speed * 1e5 / units.velocity_cm_per_s();
  phys.evolve_energy = cfg.evolve_energy;
  phys.accretion_radius = cfg.accretion_radius;

  RingSetup setup;
  setup.solution = RingSolution{cfg.disc_mass / cfg.central_mass, 1.0, phys.nu};
  setup.tau_start = cfg.tau_start;
  setup.particles = static_cast<std::size_t>(cfg.particles);
  setup.seed = static_cast<std::uint64_t>(cfg.seed);
  setup.stratified = cfg.placement == "stratified";
  setup.accretion_radius = cfg.accretion_radius;
  // nu = 0 is allowed (pure Kepler test): tau then stands for the time itself.
  const double tau_rate = 12.0 * phys.nu;  // d tau / dt with r0 = 1
  auto time_of_tau = [&](double tau) { return tau_rate > 0 ? tau / tau_rate : tau; };
  auto tau_of_time = [&](double t) { return tau_rate > 0 ? t * tau_rate : t; };

  // Refuse up front what cannot fit: ~200 bytes of fields and scratch per particle plus two
  // copies of its neighbour list (4 bytes each) while lists are rebuilt.
  const double bytes_estimate = static_cast<double>(cfg.particles) * (200.0 + 8.0 * cfg.neighbours);
  const double bytes_available = static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
  if (bytes_estimate > 0.9 * bytes_available) {
    char msg[256];
    std::snprintf(msg, sizeof msg, "problem.particles = %lld needs about %.1f GiB but this machine has %.1f GiB; use fewer particles",
                  cfg.particles, bytes_estimate / (1ull << 30), bytes_available / (1ull << 30));
    throw UserError(msg);
  }

  PhaseTimers timers;
  Particles<kDim> p;
  SnapshotMeta meta;
  double t = 0;
  {
    ScopedPhase timer(timers, "setup");
    if (!cfg.initial_conditions.empty()) {
      p = read_snapshot<kDim>(cfg.initial_conditions, &units, meta);
      t = meta.time;
    } else {
      p = make_ring(setup);
      t = time_of_tau(cfg.tau_start);
    }
  }
  std::vector<double> t_out;
  for (double tau : cfg.output_tau) t_out.push_back(time_of_tau(tau));
  if (t_out.back() <= t)
    throw UserError("every output.tau is at or before the initial time (tau = " + std::to_string(tau_of_time(t)) +
                    "); give output times after it");
  // Inputs are valid: only now touch the output directory.
  prepare_output_dir(dir, opts.overwrite);
  write_text_file(dir, "config.toml", cfg.resolved_toml);

  // h: given, or from the target mean neighbour number (analytically for the ring, measured on
  // the particles for a user's file). Constant in time and global (P98 sec. 5.3).
  const double h = cfg.smoothing_length > 0            ? cfg.smoothing_length
                   : cfg.initial_conditions.empty()    ? ring_smoothing_length(setup, cfg.neighbours)
                                                       : calibrate_smoothing_length(p.pos, p.id, cfg.neighbours);
  for (auto& hi : p.h) hi = h;

  IntegratorParams ip;
  ip.scheme = scheme_from_name(cfg.scheme);
  ip.tolerance = cfg.tolerance;
  ip.factors = {cfg.orbital_factor, cfg.force_factor, cfg.viscous_factor, cfg.courant_factor};
  if (cfg.dt_max > 0) ip.dt_max = cfg.dt_max;
  RateEvaluator<kDim> rates(kernel_from_name(cfg.kernel), h, phys, timers);
  auto integrator = make_integrator<kDim>(ip, rates);

  double accreted_mass = meta.accreted_mass, accreted_lz = meta.accreted_angular_momentum;
  accrete(p, phys.accretion_radius, accreted_mass, accreted_lz);
  if (p.size() == 0) throw UserError("no particles outside the accretion radius: check the initial conditions");
  integrator->start(p);
  check_finite(p, 0);

  meta.viscosity = phys.nu;
  meta.ring_radius = 1.0;
  meta.disc_mass = setup.solution.disc_mass;
  meta.energy = cfg.evolve_energy;
  meta.units = units;
  meta.parameters = cfg.resolved;
  auto write_output = [&](std::size_t k, long long step) {
    ScopedPhase timer(timers, "io");
    meta.time = t;
    meta.tau = tau_of_time(t);
    meta.accreted_mass = accreted_mass;
    meta.accreted_angular_momentum = accreted_lz;
    meta.step = step;
    write_snapshot(snapshot_name(dir, k), p, meta);
  };

  const std::string csv_path = (fs::path(dir) / "diagnostics.csv").string();
  std::ofstream csv(csv_path);
  if (!csv) throw UserError("cannot write '" + csv_path + "'");
  csv << "step,time,tau,dt,particles,mass,accreted_mass,kinetic_energy,internal_energy,angular_momentum,"
         "accreted_angular_momentum,wall_time\n";
  csv.precision(17);
  auto diagnostics_row = [&](long long step, double dt) {
    ScopedPhase timer(timers, "diagnostics");
    const GlobalSums s = global_sums(p, cfg.evolve_energy);
    const double wall = std::chrono::duration<double>(Clock::now() - wall_start).count();
    csv << step << ',' << t << ',' << tau_of_time(t) << ',' << dt << ',' << p.size() << ',' << s.mass << ','
        << accreted_mass << ',' << s.kinetic_energy << ',' << s.internal_energy << ',' << s.angular_momentum << ','
        << accreted_lz << ',' << wall << '\n';
  };

  write_output(0, 0);
  diagnostics_row(0, 0.0);

  std::size_t next = 0;
  while (next < t_out.size() && t_out[next] <= t) ++next;  // outputs before the start are skipped
  const double t_begin = t, t_end = t_out.back();

  long long step = 0;
  auto last_progress = Clock::now();
  std::size_t updates = p.size();  // particle rate evaluations, for the throughput figure
  while (next < t_out.size() && (cfg.max_steps == 0 || step < cfg.max_steps)) {
    if (step % kReorderInterval == 0) {
      ScopedPhase timer(timers, "reorder");
      p.gather(build_cell_grid(p.pos, p.id, 2.0 * h).sorted);
    }
    const std::size_t evals_before = rates.evaluations();
    const double dt_cap = t_out[next] - t;
    const double dt = integrator->step(p, dt_cap);
    updates += p.size() * (rates.evaluations() - evals_before);
    t = dt >= dt_cap ? t_out[next] : t + dt;
    ++step;
    accrete(p, phys.accretion_radius, accreted_mass, accreted_lz);
    check_finite(p, step);
    if (p.size() == 0) throw UserError("all particles were accreted before the last output time");
    diagnostics_row(step, dt);
    if (t >= t_out[next]) {
      write_output(++next, step);
      csv.flush();
    }
    const auto now = Clock::now();
    if (!opts.quiet && cfg.progress_interval > 0 &&
        std::chrono::duration<double>(now - last_progress).count() >= cfg.progress_interval) {
      last_progress = now;
      const double wall = std::chrono::duration<double>(now - wall_start).count();
      const double frac = (t - t_begin) / (t_end - t_begin);
      std::fprintf(stderr, "step %lld  tau %.5f  %5.1f%%  dt %.3e  N %zu  %.3g updates/s  ETA %s\n", step,
                   tau_of_time(t), 100 * frac, dt, p.size(), static_cast<double>(updates) / wall,
                   format_duration(frac > 0 ? wall * (1 - frac) / frac : 0).c_str());
    }
  }
  csv.close();
  if (!csv) throw UserError("cannot finish writing '" + csv_path + "' (disk full?)");

  RunSummary sum;
  sum.steps = step;
  sum.evaluations = rates.evaluations();
  sum.particles_final = p.size();
  sum.wall_seconds = std::chrono::duration<double>(Clock::now() - wall_start).count();
  sum.particle_updates_per_second = static_cast<double>(updates) / sum.wall_seconds;
  sum.output_dir = dir;

  write_text_file(dir, "timers.json", timers.json());
  if (!opts.trace_file.empty() && !par::trace_write(opts.trace_file))
    throw UserError("cannot write trace file '" + opts.trace_file + "'");
  if (!opts.quiet) {
    std::fprintf(stderr, "phase timers (%d threads):\n%s", par::max_threads(), timers.table().c_str());
    std::fprintf(stderr,
                 "done: %lld steps, %zu rate evaluations, %zu particles left, wall %.2f s, %.3g particle-updates/s "
                 "(%.3g per thread), %zu rejected steps\n",
                 step, sum.evaluations, sum.particles_final, sum.wall_seconds, sum.particle_updates_per_second,
                 sum.particle_updates_per_second / par::max_threads(), integrator->rejected_steps());
  }
  return sum;
}

}  // namespace sphdisk
