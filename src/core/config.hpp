#pragma once
// Run configuration: a TOML file plus `--set section.key=value` overrides. Every key is declared
// once in config.cpp with its type, default, allowed range and help text; unknown keys and invalid
// values are rejected with a one-line message naming the key and what is allowed. The resolved
// configuration (every key, defaults filled in) goes into every output.
#include <cstdint>
#include <string>
#include <vector>

namespace sphdisk {

struct Config {
  // [problem]
  std::string problem = "ring";
  long long particles = 10000;
  long long seed = 42;
  double ring_radius = 1.0;          // solar radii: the length unit r0
  double disc_mass = 1e-10;          // solar masses
  double inner_radius = 1.0, outer_radius = 5.0;  // disc: R_in, R_out in units of ring_radius
  double sigma_index = 1.0;          // disc: p of Sigma ~ R^-p
  double blast_energy = 1.0;         // sedov: code units
  double tau_start = 0.018;          // viscous time of the initial conditions (P98 5.2)
  std::string placement = "random";  // random | stratified
  std::string initial_conditions;    // HDF5 snapshot to start from instead of generating
  // [physics]
  double central_mass = 1.0;       // solar masses: the mass unit M
  double viscosity = 3e-8;         // kinematic shear viscosity, solar radii^2 / s
  double bulk_viscosity = 0.0;     // kinematic bulk viscosity, solar radii^2 / s
  double bulk_viscosity_ratio = 0; // > 0: the bulk viscosity as this multiple of the shear viscosity instead
  double alpha_ss = 0;  // > 0: nu = alpha c_s H per particle instead of viscosity (physics_params.hpp)
  std::string eos = "none";        // none | isothermal | locally_isothermal | adiabatic
  double gamma = 5.0 / 3.0;        // adiabatic index
  double sound_speed = 0.0;        // km/s (isothermal)
  double aspect_ratio = 0;        // H/R at R = r0, instead of sound_speed (0: not given)
  double alpha_max = 0;           // > 0: the sound speed at r0 raised to keep viscosity <= alpha c_s H (0: not used)
  double av_alpha = 0, av_beta = 2;  // artificial viscosity (0: none)
  std::string av_limiter = "balsara";  // balsara | none
  std::string av_switch = "morris_monaghan";  // morris_monaghan | none
  double av_alpha_min = 0.1;
  double sound_speed_index = 0;  // locally isothermal: q of c_s(R) = c_s (R / r0)^-q
  bool evolve_energy = false;
  double accretion_radius = 0.05;  // in units of ring_radius
  // [sph]
  int dimension = 2;
  std::string kernel = "cubic";
  double neighbours = 0;           // target mean neighbour number of the initial conditions; 0: "auto"
  bool neighbours_auto() const { return neighbours == 0; }
  std::string gradient_correction = "linear";  // mixed | linear | none (physics/physics_params.hpp, GradientCorrection)
  bool force_correction = false;    // moment-corrected pair gradient in the force (moment_correction.hpp)
  std::string viscous_force = "auto";  // auto | consistent | conservative (physics/physics_params.hpp)
  // The form viscous_force names: auto is the consistent form with adaptive smoothing lengths, in 2D
  // and 3D, and eq. 6's conservative form with one h for all (docs/validation.md, "One smoothing
  // length for all", "The rate a ring with pressure should have").
  std::string resolved_viscous_force() const {
    if (viscous_force != "auto") return viscous_force;
    return smoothing == "constant" ? "conservative" : "consistent";
  }
  std::string pair_density = "summation";    // summation | others | scatter (physics/physics_params.hpp, PairDensity)
  std::string smoothing = "adaptive";  // adaptive | constant (rate_evaluator.hpp)
  double smoothing_length = 0;     // constant smoothing: in units of ring_radius; 0: from sph.neighbours
  std::string pair_lists = "rescan";  // rescan | stored (rate_evaluator.hpp, PairStorage)
  // [integrator]
  std::string scheme = "block";  // block | leapfrog | respa | rk45
  double tolerance = 1e-6;
  double orbital_factor = 0.25, force_factor = 0.25, viscous_factor = 0.1, courant_factor = 0.3;
  double substep_factor = 0.05;     // respa: gravity substeps <= factor / Omega
  double dt_max = 0;               // code units; 0: no limit
  std::string viscous_update = "auto";  // auto | explicit | super_steps (integrate/integrator.hpp, ViscousUpdate)
  int max_stages = 16;             // super_steps: most Runge-Kutta-Legendre stages per step
  // The update viscous_update names: auto is super_steps for block steps with a constant viscosity,
  // with or without an isothermal pressure (block steps refuse the adiabatic one); explicit kicks
  // with the alpha viscosity, whose h^2 / nu limit does not bind while h > 3 alpha H, and with an
  // artificial viscosity, whose rates are not linear in the velocities (docs/design.md).
  std::string resolved_viscous_update() const {
    if (viscous_update != "auto") return viscous_update;
    return scheme == "block" && alpha_ss == 0 && av_alpha == 0 ? "super_steps" : "explicit";
  }
  // [output]
  std::vector<double> output_tau = {0.036, 0.054, 0.072, 0.090, 0.126};
  std::vector<double> output_times;   // code time (G = M = r0 = 1); when given, instead of output_tau
  std::vector<double> output_orbits;  // orbits of period 2 pi R^1.5 at R = output_orbit_radius, counted from t = 0
  double output_orbit_radius = 1.0;   // in units of problem.ring_radius (the code length unit)
  std::size_t output_count() const {
    return !output_times.empty() ? output_times.size() : !output_orbits.empty() ? output_orbits.size() : output_tau.size();
  }
  std::string output_dir = "runs/ring";
  double progress_interval = 5.0;  // seconds between progress lines; 0: none
  // [checkpoint] (also written at every output and on SIGTERM / SIGINT)
  long long checkpoint_every_steps = 0;     // 0: not by step count
  double checkpoint_every_tau = 0;         // simulated-time interval in viscous time; 0: off
  double checkpoint_every_seconds = 600.0;  // wall-clock interval; 0: not by wall time
  // [run]
  int threads = 0;                 // 0: OpenMP default
  std::string vector_isa = "auto";  // auto | avx2 | baseline: the widest the dispatched loops may use
  long long max_steps = 0;         // 0: no limit
  double rebalance_threshold = 1.05;  // MPI: re-cut the domains when largest rank / mean count passes this
  long long inject_nan_at_step = 0;  // testing aid for the fault path; 0: off
  long long inject_interrupt_at_substep = 0;  // testing aid: SIGINT inside a block cycle; 0: off
  long long inject_nan_at_substep = 0;  // testing aid: a NaN acceleration inside a block cycle; 0: off
  long long inject_interrupts = 1;   // how many, at that substep

  std::string resolved_toml;       // every key = value, for outputs
  // (key, value as TOML text) for every key, in declaration order (for HDF5 /Parameters)
  std::vector<std::pair<std::string, std::string>> resolved;
};

// Loads `path` (may be empty: defaults only) and applies overrides "section.key=value"; a
// relative initial-conditions path in the file is taken from the file's directory. Throws
// UserError with a one-line message on any problem.
Config load_config(const std::string& path, const std::vector<std::string>& overrides);

// Parses TOML text (used by load_config and the fuzz target). A relative problem.initial_conditions
// in the text is taken from the directory `text_dir` (that of the file holding it; "": left as
// written), one given in `overrides` from the current directory; either is then stored absolute.
Config parse_config(const std::string& toml_text, const std::string& source_name,
                    const std::vector<std::string>& overrides, const std::string& text_dir = "");

// The neighbour number sph.neighbours = "auto" stands for in a run of `particles` particles: in 2D
// 60 sqrt(N / 10,000) within [60, 120], so that the kernel holds more particles as N grows (the
// viscous torque on disordered particles falls 2-5% short at 60 neighbours and within 1% at 120,
// docs/validation.md, "A neighbour number that follows N"); in 3D 60, where wider kernels, taller
// against the disc, spread a resolved ring faster than its continuum rate (the same section).
double auto_neighbours(int dimension, double particles);

// cfg with sph.neighbours = "auto" replaced by auto_neighbours(cfg.dimension, particles) in every
// field, the resolved TOML included (so outputs and checkpoints record the number the run used);
// cfg itself when a number was given.
Config with_neighbours_resolved(const Config& cfg, double particles);

// Refuses a generated problem with adaptive h whose particles are too few for its neighbour number
// ("auto" as auto_neighbours resolves it): no kernel could hold its neighbours, and h would grow
// without end.
void check_neighbours_fit(const Config& cfg);

// All keys with their help text, for `sphdisk run --help-config`.
std::string config_reference();

// Levenshtein distance, for "did you mean" suggestions.
std::size_t edit_distance(const std::string& a, const std::string& b);

}  // namespace sphdisk
