#include "core/config.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include "core/error.hpp"
#include "core/toml.hpp"
#include "core/toml_characters.hpp"

namespace sphdisk {

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

namespace {

// One declared key: how to check a TOML node and store it in Config.
struct KeyDef {
  std::string name;  // "section.key"
  std::string type_help;
  std::string help;
  // Returns an error text (what is allowed) or "" if the node is valid; stores it on success.
  std::function<std::string(const toml::node&, Config&)> apply;
  std::function<std::string(const Config&)> current;  // value as TOML text
};

std::string toml_text(double v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);  // shortest text that reads back exactly
  std::string s(buf, res.ptr);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}
std::string toml_text(long long v) { return std::to_string(v); }
std::string toml_text(bool v) { return v ? "true" : "false"; }
std::string toml_text(const std::string& v) {
  std::string out = "\"";
  for (char c : v) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}
std::string toml_text(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t k = 0; k < v.size(); ++k) s += (k ? ", " : "") + toml_text(v[k]);
  return s + "]";
}

using Check = std::function<std::string(double)>;

Check positive() { return [](double v) { return v > 0 ? "" : "must be > 0"; }; }
Check non_negative() { return [](double v) { return v >= 0 ? "" : "must be >= 0"; }; }
Check in_range(double lo, double hi) {
  return [lo, hi](double v) {
    return v >= lo && v <= hi ? std::string() : "must be in [" + toml_text(lo) + ", " + toml_text(hi) + "]";
  };
}

KeyDef float_key(std::string name, double Config::*m, Check check, std::string help) {
  return {name, "number", std::move(help),
          [m, check](const toml::node& n, Config& c) -> std::string {
            if (!n.is_number()) return "must be a number";
            const double v = *n.value<double>();
            if (!std::isfinite(v)) return "must be a finite number";
            if (auto e = check(v); !e.empty()) return e;
            c.*m = v;
            return "";
          },
          [m](const Config& c) { return toml_text(c.*m); }};
}

template <class Int>
KeyDef int_key(std::string name, Int Config::*m, long long lo, long long hi, std::string help) {
  return {name, "integer", std::move(help),
          [m, lo, hi](const toml::node& n, Config& c) -> std::string {
            if (!n.is_integer()) return "must be an integer";
            const long long v = *n.value<long long>();
            if (v < lo || v > hi) return "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
            c.*m = static_cast<Int>(v);
            return "";
          },
          [m](const Config& c) { return toml_text(static_cast<long long>(c.*m)); }};
}

KeyDef bool_key(std::string name, bool Config::*m, std::string help) {
  return {name, "boolean", std::move(help),
          [m](const toml::node& n, Config& c) -> std::string {
            if (!n.is_boolean()) return "must be true or false";
            c.*m = *n.value<bool>();
            return "";
          },
          [m](const Config& c) { return toml_text(c.*m); }};
}

KeyDef string_key(std::string name, std::string Config::*m, std::vector<std::string> allowed, std::string help) {
  return {name, "string", std::move(help),
          [m, allowed](const toml::node& n, Config& c) -> std::string {
            if (!n.is_string()) return "must be a string";
            const std::string v = *n.value<std::string>();
            if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), v) == allowed.end()) {
              std::string e = "must be one of";
              for (const auto& a : allowed) e += " \"" + a + "\"";
              return e;
            }
            c.*m = v;
            return "";
          },
          [m](const Config& c) { return toml_text(c.*m); }};
}

// A string key that also takes the booleans of an earlier form of it: true -> if_true, false -> if_false.
KeyDef string_or_bool_key(std::string name, std::string Config::*m, std::vector<std::string> allowed, std::string if_true,
                          std::string if_false, std::string help) {
  KeyDef k = string_key(std::move(name), m, std::move(allowed), std::move(help));
  k.apply = [strings = k.apply, m, if_true, if_false](const toml::node& n, Config& c) -> std::string {
    if (!n.is_boolean()) return strings(n, c);
    c.*m = *n.value<bool>() ? if_true : if_false;
    return "";
  };
  return k;
}

// sph.neighbours: a number in [4, 10000] or "auto" (stored as 0, Config::neighbours_auto).
KeyDef neighbours_key(std::string name, std::string help) {
  KeyDef k = float_key(std::move(name), &Config::neighbours, in_range(4, 10000), std::move(help));
  k.type_help = "number or \"auto\"";
  k.apply = [numbers = k.apply](const toml::node& n, Config& c) -> std::string {
    if (!n.is_string()) return n.is_number() ? numbers(n, c) : "must be a number in [4, 10000] or \"auto\"";
    if (*n.value<std::string>() != "auto") return "must be a number in [4, 10000] or \"auto\"";
    c.neighbours = 0;
    return "";
  };
  k.current = [numbers = k.current](const Config& c) { return c.neighbours_auto() ? std::string("\"auto\"") : numbers(c); };
  return k;
}

// may_be_empty: an optional list ([] = not given).
KeyDef increasing_list_key(std::string name, std::vector<double> Config::*m, std::string help, bool may_be_empty = false) {
  return {name, "list of numbers", std::move(help),
          [m, may_be_empty](const toml::node& n, Config& c) -> std::string {
            const toml::array* a = n.as_array();
            if (a && a->empty() && may_be_empty) {
              (c.*m).clear();
              return "";
            }
            if (!a || a->empty()) return "must be a non-empty list of numbers, e.g. [0.036, 0.09]";
            std::vector<double> v;
            for (const auto& e : *a) {
              if (!e.is_number()) return "must be a list of numbers";
              v.push_back(*e.value<double>());
              if (!std::isfinite(v.back())) return "must hold finite numbers";
              if (v.size() > 1 && !(v.back() > v[v.size() - 2])) return "must be strictly increasing";
            }
            c.*m = v;
            return "";
          },
          [m](const Config& c) { return toml_text(c.*m); }};
}

const std::vector<KeyDef>& schema() {
  static const std::vector<KeyDef> keys = {
      string_key("problem.type", &Config::problem, {"ring", "disc", "sedov"}, "set-up: the viscously spreading ring (P98 sec. 5), a power-law disc Sigma ~ R^-p between problem.inner_radius and problem.outer_radius (Phantom's set-up; in 3D in vertical equilibrium), or a Sedov-Taylor blast wave (no point mass: a uniform cube, or square in 2D, of side 1 and mass 1 in code units on a lattice of about problem.particles, with problem.blast_energy put into the particles at its centre; needs physics.eos = \"adiabatic\")"),
      float_key("problem.blast_energy", &Config::blast_energy, positive(), "sedov: the energy put into the central particles, in code units (the cube has side 1 and mass 1; the surrounding gas has a pressure 1e-5 of it per unit volume)"),
      int_key("problem.particles", &Config::particles, 1, 2'000'000'000, "number of SPH particles N"),
      int_key("problem.seed", &Config::seed, 0, (1LL << 62), "seed of the random particle placement (same seed, same particles)"),
      float_key("problem.ring_radius", &Config::ring_radius, positive(), "initial ring radius r0 in solar radii (the code length unit)"),
      float_key("problem.disc_mass", &Config::disc_mass, positive(), "disc mass m in solar masses"),
      float_key("problem.inner_radius", &Config::inner_radius, positive(), "disc: inner edge R_in in units of problem.ring_radius"),
      float_key("problem.outer_radius", &Config::outer_radius, positive(), "disc: outer edge R_out in units of problem.ring_radius"),
      float_key("problem.sigma_index", &Config::sigma_index, in_range(-3, 3), "disc: p of the surface density Sigma ~ R^-p (Phantom's pindex)"),
      float_key("problem.tau_start", &Config::tau_start, positive(), "viscous time tau = 12 nu t / r0^2 of the initial conditions"),
      string_key("problem.placement", &Config::placement, {"random", "stratified"}, "radii drawn at random, or stratified (low noise)"),
      string_key("problem.initial_conditions", &Config::initial_conditions, {}, "HDF5 snapshot to start from (\"\": generate the ring)"),
      float_key("physics.central_mass", &Config::central_mass, positive(), "central point mass M in solar masses (the code mass unit)"),
      float_key("physics.viscosity", &Config::viscosity, non_negative(), "kinematic shear viscosity nu in solar radii^2 / s"),
      float_key("physics.alpha_ss", &Config::alpha_ss, in_range(0, 10), "Shakura-Sunyaev alpha: nu = alpha c_s H per particle, H = c_s / Omega (Phantom's irealvisc = 2), instead of physics.viscosity (then 0); needs an equation of state, and output.times or output.orbits (no viscous time); 0: the constant physics.viscosity"),
      float_key("physics.bulk_viscosity", &Config::bulk_viscosity, non_negative(), "kinematic bulk viscosity zeta/rho in solar radii^2 / s"),
      float_key("physics.bulk_viscosity_ratio", &Config::bulk_viscosity_ratio, in_range(0, 100), "the bulk viscosity as this multiple of the shear viscosity (of each particle's with physics.alpha_ss), instead of physics.bulk_viscosity (which is then 0): from 2/3 on a Keplerian disc has no viscous overstability, the growing radial waves of a Navier-Stokes disc without bulk viscosity (docs/physics.md sec. 4, \"Viscous overstability\"; tools/viscous_overstability.py); configs/ring_cold.toml takes 1; 0: not used"),
      string_key("physics.eos", &Config::eos, {"none", "isothermal", "locally_isothermal", "adiabatic"}, "equation of state: none (pressureless, as in the ring test), isothermal (P = c_s^2 rho), locally_isothermal (P = c_s(R)^2 rho, c_s(R) = physics.sound_speed (R / r0)^-physics.sound_speed_index, R the cylindrical radius: Phantom's ieos = 3), adiabatic (P = (physics.gamma - 1) rho u with each particle's internal energy u: Phantom's ieos = 2; needs physics.evolve_energy = true)"),
      float_key("physics.gamma", &Config::gamma, in_range(1.0001, 10), "adiabatic: the adiabatic index gamma of P = (gamma - 1) rho u"),
      float_key("physics.sound_speed", &Config::sound_speed, non_negative(), "isothermal sound speed in km/s (locally_isothermal: at R = r0)"),
      float_key("physics.aspect_ratio", &Config::aspect_ratio, in_range(0, 1), "H/R = c_s / v_Kepler at R = r0, instead of physics.sound_speed (which is then 0): the thickness a locally isothermal or isothermal disc has in vertical equilibrium; 0: physics.sound_speed is given"),
      float_key("physics.alpha_max", &Config::alpha_max, in_range(0, 100), "the largest alpha = nu Omega / c_s^2 at r0 the constant physics.viscosity may have: the sound speed given by physics.aspect_ratio or physics.sound_speed is raised to (nu Omega(r0) / alpha_max)^1/2 where it is lower, and with neither given is that; the cold ring (configs/ring_cold.toml) takes 2 alone, a sound speed that follows the viscosity (measured from 1/32 to 16 times the paper's, docs/validation.md); 0: not used"),
      float_key("physics.sound_speed_index", &Config::sound_speed_index, in_range(-2, 2), "locally_isothermal: q of c_s(R) = c_s (R / r0)^-q (Phantom's qfacdisc; 0.25 for its test disc)"),
      float_key("physics.av_alpha", &Config::av_alpha, in_range(0, 10), "artificial viscosity (Monaghan 1997 with the signal velocity, Phantom's form): alpha of its signal velocity alpha c_s + beta |v_ij . r_ij / r_ij| over approaching pairs; 0: none (the ring's viscosity is physics.viscosity alone); needs an equation of state; its signal speeds limit the steps (integrator.courant_factor)"),
      float_key("physics.av_beta", &Config::av_beta, in_range(0, 10), "artificial viscosity: beta of the signal velocity"),
      string_key("physics.av_limiter", &Config::av_limiter, {"balsara", "none"}, "artificial viscosity: balsara scales each particle's share by |div v| / (|div v| + |curl v| + 1e-4 c_s / h) (Balsara 1995), which keeps it off shear flows such as a Keplerian disc; none: the full alpha everywhere"),
      string_key("physics.av_switch", &Config::av_switch, {"morris_monaghan", "none"}, "artificial viscosity: morris_monaghan gives each particle its own alpha, raised towards physics.av_alpha where the flow converges (max(-div v, 0)) and decaying to physics.av_alpha_min over ~10 sound-crossing times of its kernel (Morris & Monaghan 1997, decay constant 0.1): shock capturing where there are shocks only; none: alpha = physics.av_alpha everywhere"),
      float_key("physics.av_alpha_min", &Config::av_alpha_min, in_range(0, 10), "artificial viscosity with physics.av_switch = \"morris_monaghan\": the alpha each particle decays to away from shocks (at most physics.av_alpha)"),
      bool_key("physics.evolve_energy", &Config::evolve_energy, "integrate the internal energy (viscous heating)"),
      float_key("physics.accretion_radius", &Config::accretion_radius, non_negative(), "accretion radius in units of ring_radius"),
      int_key("sph.dimension", &Config::dimension, 2, 3, "spatial dimension"),
      string_key("sph.kernel", &Config::kernel, {"cubic", "wendland_c2", "wendland_c4"}, "smoothing kernel"),
      neighbours_key("sph.neighbours", "target neighbour number: sets eta (adaptive) or the global h from the initial conditions (constant); \"auto\" (the default): in 2D 60 sqrt(N / 10,000) within [60, 120], N the run's particles at its start (60 at 10,000, 104 at 30,000, 120 from 40,000 on: the viscous torque on disordered particles falls 2-5% short at 60 neighbours and within 1% at 120, docs/validation.md), in 3D 60; outputs record the number used"),
      string_or_bool_key("sph.gradient_correction", &Config::gradient_correction, {"mixed", "linear", "none"}, "linear", "none", "the kernel gradient of the velocity gradient (eq. 8) and of the consistent viscous force: linear: made exact for linear fields (C = M^-1); mixed: the gradient of the Shepard-normalised kernel made exact for linear fields (Bonet & Lok 1999): a particle's own velocity does not enter its gradient, which removes the growing modes of the viscous rates on close pairs (docs/validation.md); about 1.8x the ring's run time; none: eq. 8 as printed (the consistent force keeps C); true and false, the key's earlier values, mean linear and none"),
      string_key("sph.smoothing", &Config::smoothing, {"adaptive", "constant"}, "adaptive: h_i = eta (m_i/rho_i)^(1/D) with eta from sph.neighbours (Phantom, GADGET); constant: one global h (P98 sec. 5.3)"),
      string_key("sph.viscous_force", &Config::viscous_force, {"auto", "consistent", "conservative"}, "divergence of the viscous stress (eq. 6): auto: consistent with adaptive smoothing lengths, conservative with sph.smoothing = \"constant\" (with one h the wings' kernels hold few neighbours and the consistent form throws particles out of the ring); consistent: zero for a constant stress and exact for linear ones on any particle set (linear momentum conserved to the discretisation error; in 3D a disc whose kernels are taller than its scale height gets a net torque, which vanishes as h/H falls below 1, docs/validation.md); conservative: eq. 6 as printed (momentum and energy conserved to round-off, but too little spreading where viscosity acts within an orbit across a kernel, docs/validation.md)"),
      string_key("sph.pair_density", &Config::pair_density, {"summation", "others", "scatter"}, "with the consistent viscous force, the densities whose ratio gives S . grad ln rho: summation: the summed densities (a contrast too small by a fraction that does not shrink with N); others: each without the pair's own two terms (rho - m W(0, h) - m' W(r, h)): the ring's spreading rate within 1% at 30k-200k, but stronger radial ripples from 100k on and 2x the force loop's time (docs/validation.md, \"The density a pair compares\"); scatter: sum_j m_j W(r_ij, h_j), from the neighbours' kernels, without the gather sum's bias in sparse wings: the pressureless ring's rate within 1.5% at 10k-100k, but without a bulk viscosity its particles clump from 30k on (the viscous overstability, docs/physics.md sec. 4) (docs/validation.md, \"A density without the gather bias: the scatter sum\")"),
      bool_key("sph.force_correction", &Config::force_correction, "with sph.viscous_force = \"conservative\": eq. 6 with the moment-corrected, pair-symmetrised kernel gradient (IAD0); momentum and energy stay exact"),
      float_key("sph.smoothing_length", &Config::smoothing_length, non_negative(), "smoothing length h in units of ring_radius (0: from sph.neighbours)"),
      string_key("sph.pair_lists", &Config::pair_lists, {"rescan", "stored"}, "rescan: each pair loop searches its pairs anew and nothing is stored (least memory; with block steps as fast as stored); stored: neighbour lists and pair factors built once per evaluation (faster with the leapfrog, respa and Runge-Kutta schemes, ~2.5x the memory)"),
      string_key("integrator.scheme", &Config::scheme, {"block", "leapfrog", "respa", "rk45"}, "time integrator (block: individual power-of-two timesteps with gravity substeps, fastest at equal accuracy from 100k particles)"),
      float_key("integrator.tolerance", &Config::tolerance, in_range(1e-14, 0.1), "relative error tolerance per step (rk45)"),
      float_key("integrator.orbital_factor", &Config::orbital_factor, in_range(1e-6, 1), "dt <= factor / Omega (every scheme; respa, block: the hydrodynamic step, gravity substepped)"),
      float_key("integrator.substep_factor", &Config::substep_factor, in_range(1e-6, 1),
                "respa, block: gravity substeps <= factor / Omega"),
      float_key("integrator.force_factor", &Config::force_factor, in_range(1e-6, 1), "dt <= factor sqrt(h / |a|)"),
      float_key("integrator.viscous_factor", &Config::viscous_factor, in_range(1e-6, 10), "dt <= factor h^2 / nu"),
      float_key("integrator.courant_factor", &Config::courant_factor, in_range(1e-6, 1), "dt <= factor h / c_s"),
      string_key("integrator.viscous_update", &Config::viscous_update, {"auto", "explicit", "super_steps"}, "explicit: kicks, the steps bounded by integrator.viscous_factor h^2 / nu; super_steps (block steps, no pressure or an isothermal one): the viscous rates advanced at each step's end by forward-Euler substeps or Runge-Kutta-Legendre stages, as few as the step needs in explicit limits h^2 / nu (0.5 h^2 / nu with the conservative force; s stages reach (s^2 + s - 2) / 4 of them), so integrator.viscous_factor does not bound the steps; auto: super_steps for block steps with a constant viscosity (physics.viscosity) and no artificial viscosity, else explicit"),
      int_key("integrator.max_stages", &Config::max_stages, 2, 1000, "super_steps: most Runge-Kutta-Legendre stages per update (steps up to (s^2 + s - 2) / 4 explicit limits: h^2 / nu with the consistent force, 0.5 h^2 / nu with the conservative one)"),
      float_key("integrator.dt_max", &Config::dt_max, non_negative(), "largest timestep in code units (0: no limit)"),
      increasing_list_key("output.tau", &Config::output_tau, "viscous times tau = 12 nu t / r0^2 of the snapshots; the run ends at the last (unless output.times or output.orbits is given)"),
      increasing_list_key("output.times", &Config::output_times, "times of the snapshots in code units (G = M = r0 = 1, one orbit at r0 is 2 pi), instead of output.tau; [] = not given", true),
      increasing_list_key("output.orbits", &Config::output_orbits, "times of the snapshots in orbits at output.orbit_radius (counted from t = 0), instead of output.tau; [] = not given", true),
      float_key("output.orbit_radius", &Config::output_orbit_radius, positive(), "radius, in units of problem.ring_radius, whose orbital period output.orbits counts"),
      string_key("output.dir", &Config::output_dir, {}, "output directory"),
      float_key("output.progress_interval", &Config::progress_interval, non_negative(), "seconds between progress lines (0: none)"),
      int_key("checkpoint.every_steps", &Config::checkpoint_every_steps, 0, (1LL << 62), "write a checkpoint every this many steps (0: off; checkpoints are also written at every output and on SIGTERM/SIGINT)"),
      float_key("checkpoint.every_tau", &Config::checkpoint_every_tau, non_negative(), "write a checkpoint each time the viscous time tau passes a multiple of this (0: off)"),
      float_key("checkpoint.every_seconds", &Config::checkpoint_every_seconds, non_negative(), "write a checkpoint every this many wall-clock seconds (0: off)"),
      int_key("run.threads", &Config::threads, 0, 4096, "threads (0: OpenMP default, e.g. OMP_NUM_THREADS)"),
      string_key("run.vector_isa", &Config::vector_isa, {"auto", "avx2", "baseline"},
                 "widest vector instructions of the hand-dispatched loops: auto (the CPU's widest: AVX-512, AVX2 or baseline), avx2, or baseline (SSE2); the same bits with each, only the speed differs (`sphdisk --version` names the CPU's)"),
      int_key("run.inject_nan_at_step", &Config::inject_nan_at_step, 0, (1LL << 62), "testing aid: make one velocity NaN at this step to exercise the fault handling (0: off)"),
      int_key("run.inject_interrupt_at_substep", &Config::inject_interrupt_at_substep, 0, (1LL << 62), "testing aid: raise SIGINT after this substep of the run (block cycles' ticks, counted from the run's start) to exercise stops inside a step (0: off)"),
      int_key("run.inject_nan_at_substep", &Config::inject_nan_at_substep, 0, (1LL << 62), "testing aid: make one acceleration NaN after this substep of the run (block cycles' ticks) to exercise the fault handling inside a step (0: off)"),
      int_key("run.inject_interrupts", &Config::inject_interrupts, 1, 2, "testing aid: how many SIGINTs run.inject_interrupt_at_substep raises (2: the step is abandoned)"),
      int_key("run.max_steps", &Config::max_steps, 0, (1LL << 62), "stop after this many steps (0: no limit)"),
      float_key("run.rebalance_threshold", &Config::rebalance_threshold, in_range(1, 100), "over MPI ranks: the domains are cut anew when the largest rank's particle count over the mean passes this (1: every step)"),
  };
  return keys;
}

[[noreturn]] void unknown_key(const std::string& key, const std::string& where) {
  std::string best;
  std::size_t best_d = 1000;
  for (const auto& k : schema()) {
    const std::size_t d = edit_distance(key, k.name);
    if (d < best_d) best_d = d, best = k.name;
  }
  std::string msg = where + ": unknown key '" + key + "'";
  if (best_d <= 4) msg += "; did you mean '" + best + "'?";
  msg += " (`sphdisk run --help-config` lists all keys)";
  throw UserError(msg);
}

// Flattens nested tables into "a.b" keys.
void flatten(const toml::table& t, const std::string& prefix, std::vector<std::pair<std::string, const toml::node*>>& out) {
  for (const auto& [k, v] : t) {
    const std::string name = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const toml::table* sub = v.as_table())
      flatten(*sub, name, out);
    else
      out.emplace_back(name, &v);
  }
}

// Keys of modes that were measured and retired (docs/design.md, "Modes kept and retired"): the value
// that means what the code now always does is accepted (checkpoints record every key) and changes
// nothing; any other value is refused, naming the replacement.
struct RetiredKey {
  const char* name;
  double inert_value;
  const char* replacement;
};
constexpr RetiredKey kRetiredKeys[] = {
    {"sph.list_skin", 0.0,
     "neighbour lists are built anew at every evaluation (reused lists with a skin were 35% slower on the ring at "
     "3x the memory); remove the key"},
};

// Values of kept keys that were measured and retired: refused, naming the replacement (a run
// stored with one resumes with --set naming it).
struct RetiredValue {
  const char* name;
  const char* value;
  const char* replacement;
};
constexpr RetiredValue kRetiredValues[] = {
    {"integrator.scheme", "rk23",
     "rk45 reaches the same accuracy with 1.1-10x fewer rate evaluations at every tolerance (docs/design.md, \"Modes "
     "kept and retired\"); set integrator.scheme = \"rk45\" (to resume such a run: --set 'integrator.scheme=\"rk45\"')"},
};

// True: name is a retired key given its inert value (nothing to do). Throws for any other value,
// and for a retired value of a kept key.
bool retired_key(const std::string& name, const toml::node& node, const std::string& where) {
  for (const RetiredValue& v : kRetiredValues)
    if (name == v.name && node.is_string() && *node.value<std::string>() == v.value)
      throw UserError(where + ": " + name + " = \"" + v.value + "\" was retired: " + v.replacement);
  for (const RetiredKey& k : kRetiredKeys) {
    if (name != k.name) continue;
    if (node.is_number() && *node.value<double>() == k.inert_value) return true;
    throw UserError(where + ": " + name + " was retired: " + k.replacement);
  }
  return false;
}

const KeyDef* find_key(const std::string& name) {
  for (const auto& k : schema())
    if (k.name == name) return &k;
  return nullptr;
}

void apply_node(const std::string& name, const toml::node& node, Config& c, const std::string& where) {
  if (retired_key(name, node, where)) return;
  const KeyDef* def = find_key(name);
  if (!def) unknown_key(name, where);
  if (auto e = def->apply(node, c); !e.empty()) throw UserError(where + ": " + name + " " + e + " (" + def->help + ")");
}

void check_consistency(const Config& c) {
  const bool disc = c.problem == "disc" && c.initial_conditions.empty();
  if (disc && !(c.inner_radius < c.outer_radius))
    throw UserError("config: problem.inner_radius = " + toml_text(c.inner_radius) + " must be below problem.outer_radius = " +
                    toml_text(c.outer_radius));
  if (disc && c.accretion_radius >= c.inner_radius)
    throw UserError("config: physics.accretion_radius = " + toml_text(c.accretion_radius) +
                    " must be below problem.inner_radius = " + toml_text(c.inner_radius) + " (particles inside are removed)");
  if (disc && c.output_times.empty() && c.output_orbits.empty())
    throw UserError("config: a disc has no viscous time tau of its own; give output.times or output.orbits");
  if (!disc && c.problem != "sedov" && c.accretion_radius >= 1.0)
    throw UserError("config: physics.accretion_radius = " + toml_text(c.accretion_radius) +
                    " must be < 1 (it is in units of ring_radius: particles inside are removed)");
  if (!c.output_times.empty() && !c.output_orbits.empty())
    throw UserError("config: give the output times once: output.times (code units) or output.orbits, not both");
  if (c.output_times.empty() && c.output_orbits.empty() && c.initial_conditions.empty() && c.output_tau.front() <= c.tau_start)
    throw UserError("config: output.tau must start after problem.tau_start = " + toml_text(c.tau_start) +
                    " (got " + toml_text(c.output_tau.front()) + ")");
  if (c.alpha_ss > 0 && c.eos == "none")
    throw UserError("config: physics.alpha_ss > 0 needs a sound speed (nu = alpha c_s H): set physics.eos = "
                    "\"locally_isothermal\" or \"isothermal\" with physics.sound_speed");
  if (c.alpha_ss > 0 && c.viscosity > 0)
    throw UserError("config: physics.alpha_ss > 0 replaces physics.viscosity; set physics.viscosity = 0");
  if (c.alpha_ss > 0 && c.output_times.empty() && c.output_orbits.empty())
    throw UserError("config: with physics.alpha_ss > 0 there is no viscous time tau; give output.times or output.orbits");
  if (c.sound_speed > 0 && c.aspect_ratio > 0)
    throw UserError("config: give the sound speed once: physics.sound_speed (km/s) or physics.aspect_ratio (H/R at r0), not both");
  if (c.bulk_viscosity > 0 && c.bulk_viscosity_ratio > 0)
    throw UserError("config: give the bulk viscosity once: physics.bulk_viscosity (solar radii^2 / s) or "
                    "physics.bulk_viscosity_ratio (a multiple of the shear viscosity), not both");
  if (c.alpha_max > 0 && !(c.viscosity > 0))
    throw UserError("config: physics.alpha_max bounds the alpha of the constant physics.viscosity, which is 0; "
                    "set physics.viscosity > 0 or physics.alpha_max = 0");
  const bool adiabatic = c.eos == "adiabatic";
  if (adiabatic && !c.evolve_energy)
    throw UserError("config: physics.eos = \"adiabatic\" takes the pressure from each particle's internal energy; set physics.evolve_energy = true");
  if (adiabatic && (c.sound_speed > 0 || c.aspect_ratio > 0 || c.alpha_max > 0))
    throw UserError("config: physics.eos = \"adiabatic\" has each particle's own sound speed; set physics.sound_speed, "
                    "physics.aspect_ratio and physics.alpha_max to 0");
  if (adiabatic && c.alpha_ss > 0)
    throw UserError("config: physics.alpha_ss needs the sound speed of physics.eos = \"locally_isothermal\" or \"isothermal\", not \"adiabatic\"");
  if (adiabatic && c.initial_conditions.empty() && c.problem != "sedov")
    throw UserError("config: physics.eos = \"adiabatic\" needs each particle's internal energy: use problem.type = \"sedov\", or "
                    "problem.initial_conditions with InternalEnergy");
  if (adiabatic && c.scheme != "leapfrog" && c.scheme != "respa")
    throw UserError("config: physics.eos = \"adiabatic\" runs with integrator.scheme = \"leapfrog\" or \"respa\": block steps have no "
                    "limiter that wakes the particles a shock reaches, and the Runge-Kutta error control stalls at a blast's start");
  const bool sedov = c.problem == "sedov" && c.initial_conditions.empty();
  if (sedov && !adiabatic)
    throw UserError("config: problem.type = \"sedov\" is a blast wave in an ideal gas: set physics.eos = \"adiabatic\" and physics.evolve_energy = true");
  if (sedov && c.output_times.empty())
    throw UserError("config: a blast wave has neither viscous time nor orbits; give output.times (code units)");
  if (!adiabatic && c.eos != "none" && c.sound_speed <= 0 && c.aspect_ratio <= 0 && c.alpha_max <= 0)
    throw UserError("config: physics.eos = \"" + c.eos + "\" needs physics.sound_speed > 0 (km/s), physics.aspect_ratio > 0 (H/R at r0) "
                    "or physics.alpha_max > 0");
  if (c.av_alpha > 0 && c.eos == "none")
    throw UserError("config: physics.av_alpha > 0 needs a sound speed for its signal velocity: set physics.eos with "
                    "physics.aspect_ratio or physics.sound_speed");
  if (c.av_alpha > 0 && c.av_switch == "morris_monaghan" && c.av_alpha_min > c.av_alpha)
    throw UserError("config: physics.av_alpha_min = " + toml_text(c.av_alpha_min) + " is above physics.av_alpha = " + toml_text(c.av_alpha) +
                    ", the largest alpha the switch gives; lower physics.av_alpha_min or raise physics.av_alpha");
  if (c.eos == "none" && c.aspect_ratio > 0)
    throw UserError("config: physics.aspect_ratio sets the sound speed of an equation of state; set physics.eos = \"locally_isothermal\" or \"isothermal\"");
  if (c.eos == "none" && c.alpha_max > 0)
    throw UserError("config: physics.alpha_max sets the sound speed of an equation of state; set physics.eos = \"locally_isothermal\" or \"isothermal\"");
  if (c.dimension == 3 && c.eos == "none" && c.initial_conditions.empty())
    throw UserError("config: sph.dimension = 3 needs pressure to hold the disc up: set physics.eos = \"locally_isothermal\" and "
                    "physics.aspect_ratio (H/R at r0, e.g. 0.05)");
  if (c.output_dir.empty()) throw UserError("config: output.dir must not be empty");
  if (c.force_correction && c.resolved_viscous_force() != "conservative")
    throw UserError("config: sph.force_correction = true corrects the conservative form of eq. 6; add "
                    "sph.viscous_force = \"conservative\" (the consistent form, the default with adaptive h, is corrected already)");
  if (c.viscous_update == "super_steps" && c.scheme != "block")
    throw UserError("config: integrator.viscous_update = \"super_steps\" needs integrator.scheme = \"block\"");
}

// An input file's path as the run will open it: a relative one taken from `from` (a configuration
// file's directory, or the current one), made absolute so that config.toml and checkpoints name the
// same file wherever they are read.
std::string input_path(const std::string& path, const std::filesystem::path& from) {
  if (path.empty() || std::filesystem::path(path).is_absolute()) return path;
  return std::filesystem::absolute(from / path).lexically_normal().string();
}

}  // namespace

Config parse_config(const std::string& toml_text_in, const std::string& source_name,
                    const std::vector<std::string>& overrides, const std::string& text_dir) {
  Config c;
  check_toml_characters(toml_text_in, source_name);
  toml::table table;
  try {
    table = toml::parse(toml_text_in, source_name);
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    throw UserError(source_name + ":" + std::to_string(b.line) + ":" + std::to_string(b.column) +
                    ": invalid TOML: " + one_line(std::string(e.description())));
  } catch (const TomlCheckFailed&) {
    throw UserError(source_name + ": invalid TOML (malformed key or table header)");
  }
  std::vector<std::pair<std::string, const toml::node*>> entries;
  flatten(table, "", entries);
  // A key that an override sets takes the override's value alone: a stored configuration naming a
  // retired value resumes with --set naming its replacement.
  const auto overridden = [&](const std::string& name) {
    return std::any_of(overrides.begin(), overrides.end(), [&](const std::string& o) { return o.rfind(name + "=", 0) == 0; });
  };
  for (const auto& [name, node] : entries)
    if (!overridden(name)) apply_node(name, *node, c, source_name);
  if (!text_dir.empty()) c.initial_conditions = input_path(c.initial_conditions, text_dir);

  for (const std::string& o : overrides) {
    const auto eq = o.find('=');
    if (eq == std::string::npos || eq == 0)
      throw UserError("--set '" + o + "': expected section.key=value, e.g. --set problem.particles=100000");
    const std::string key = o.substr(0, eq), value = o.substr(eq + 1);
    toml::table one;
    try {
      check_toml_characters("v = " + value, "--set");  // keeps odd bytes away from toml++ here too
      one = toml::parse("v = " + value);
    } catch (const std::exception&) {  // UserError, toml::parse_error or TomlCheckFailed
      one = toml::table{{"v", value}};  // a bare word is a string: --set integrator.scheme=rk45
    }
    apply_node(key, *one.get("v"), c, "--set " + key);
    if (key == "problem.initial_conditions") c.initial_conditions = input_path(c.initial_conditions, ".");
  }
  check_consistency(c);

  std::string section;
  std::ostringstream os;
  for (const auto& k : schema()) {
    const std::string sec = k.name.substr(0, k.name.find('.'));
    if (sec != section) {
      os << (section.empty() ? "" : "\n") << "[" << sec << "]\n";
      section = sec;
    }
    const std::string v = k.current(c);
    os << k.name.substr(k.name.find('.') + 1) << " = " << v << "\n";
    c.resolved.emplace_back(k.name, v);
  }
  c.resolved_toml = os.str();
  return c;
}

double auto_neighbours(int dimension, double particles) {
  if (dimension != 2) return 60;
  return std::round(std::clamp(60 * std::sqrt(particles / 1e4), 60.0, 120.0));
}

Config with_neighbours_resolved(const Config& cfg, double particles) {
  if (!cfg.neighbours_auto()) return cfg;
  // Parsed again from its own resolved text, so that every field and the text agree.
  return parse_config(cfg.resolved_toml, "the resolved configuration",
                      {"sph.neighbours=" + toml_text(auto_neighbours(cfg.dimension, particles))});
}

Config load_config(const std::string& path, const std::vector<std::string>& overrides) {
  std::string text;
  if (!path.empty()) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
      throw UserError("'" + path + "' is a directory, not a configuration file; give a TOML file (e.g. configs/ring.toml), "
                      "or continue the run in it with sphdisk resume " + path);
    std::ifstream in(path, std::ios::binary);
    if (!in) throw UserError("cannot read configuration file '" + path + "': check the path");
    std::ostringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  const std::string dir = path.empty() ? "" : std::filesystem::absolute(path).parent_path().string();
  return parse_config(text, path.empty() ? "defaults" : path, overrides, dir);
}

void check_neighbours_fit(const Config& cfg) {
  if (!cfg.initial_conditions.empty() || cfg.smoothing != "adaptive") return;
  const double neighbours = cfg.neighbours_auto() ? auto_neighbours(cfg.dimension, static_cast<double>(cfg.particles)) : cfg.neighbours;
  if (static_cast<double>(cfg.particles) >= neighbours + 1) return;
  char why[200];
  std::snprintf(why, sizeof why, "problem.particles = %lld is too few for %g neighbours per particle (sph.neighbours); "
                "give at least %.0f particles, or a smaller sph.neighbours", cfg.particles, neighbours, std::ceil(neighbours) + 1);
  throw UserError(why);
}

std::string config_reference() {
  std::ostringstream os;
  const Config defaults;
  for (const auto& k : schema())
    os << k.name << " = " << k.current(defaults) << "    # " << k.type_help << ": " << k.help << "\n";
  return os.str();
}

}  // namespace sphdisk
