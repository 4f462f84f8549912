// sphdisk command-line interface (docs/formats.md, "Command line"): run, resume, analyze, report, sweep.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <thread>
#include <vector>

#include <unistd.h>

#include "app/ring_analysis.hpp"
#include "app/sedov_analysis.hpp"
#include "app/run_directory.hpp"
#include "app/run_log.hpp"
#include "app/simulation.hpp"
#include "app/disc_plane.hpp"
#include "app/disc_profiles.hpp"
#include "app/sweep.hpp"
#include "core/build_info.hpp"
#include "core/vector_isa.hpp"
#include "core/config.hpp"
#include "core/error.hpp"
#include "core/units.hpp"
#include "io/snapshot.hpp"
#include "parallel/communicator.hpp"

#ifndef SPHDISK_SOURCE_DIR
#define SPHDISK_SOURCE_DIR "."
#endif

namespace {

// The comparison with an analytic solution, or a disc's profiles; at the end of a run also into its run.log.
int cmd_analyze(const std::string& path, const std::string& json_path, int bins) {
  sphdisk::SnapshotMeta meta;
  // Kept in the file's own code units, in which the ring header values are given. A blast wave
  // against its similarity solution; a 3D disc's particles seen from above (vertically integrated
  // by the radial bins), their heights kept aside; the ring against its analytic solution, any
  // other disc as radial profiles.
  std::string table, json;
  auto sedov = [&](const auto& particles) {
    const auto c = sphdisk::compare_sedov(particles, meta, bins);
    table = sphdisk::sedov_comparison_table(c), json = sphdisk::sedov_comparison_json(c);
  };
  auto disc = [&](const sphdisk::Particles<2>& p, const std::vector<double>* heights) {
    if (sphdisk::is_ring_snapshot(meta)) {
      const auto c = sphdisk::compare_ring(p, meta, bins);
      table = sphdisk::ring_comparison_table(c), json = sphdisk::ring_comparison_json(c);
    } else {
      const auto d = sphdisk::disc_profiles(p, meta, bins, 0, 0, heights);
      table = sphdisk::disc_profiles_table(d), json = sphdisk::disc_profiles_json(d);
    }
  };
  if (sphdisk::snapshot_dimension(path) != 3) {
    const auto p = sphdisk::read_snapshot<2>(path, nullptr, meta);
    if (meta.problem == "sedov") sedov(p);
    else disc(p, nullptr);
  } else {
    const auto p3 = sphdisk::read_snapshot<3>(path, nullptr, meta);
    if (meta.problem == "sedov") {
      sedov(p3);
    } else {
      std::vector<double> heights;
      for (const auto& x : p3.pos) heights.push_back(x[2]);
      disc(sphdisk::seen_from_above(p3), &heights);
    }
  }
  std::cout << table;
  sphdisk::run_log::write(table);
  if (!json_path.empty()) {
    std::ofstream f(json_path);
    f << json;
    if (!f)
      throw sphdisk::UserError("cannot write --json '" + json_path + "': " + std::strerror(errno) +
                               "; give a path in a writable directory");
  }
  return 0;
}

// A run stopped by SIGTERM/SIGINT (with its checkpoint written, or, after a second signal inside a
// block cycle, from its last one): exit 75 (EX_TEMPFAIL, "try again").
int report_interrupted(const sphdisk::RunSummary& summary) {
  sphdisk::run_log::print(stderr, "sphdisk: %s\n", sphdisk::interruption_note(summary).c_str());
  return 75;
}

int cmd_report(const std::string& dir) {
  std::error_code ec;
  if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec))
    throw sphdisk::UserError("'" + dir + "' is a file, not a run directory; give the directory a run wrote (sphdisk report runs/ring)");
  const std::string script = std::string(SPHDISK_SOURCE_DIR) + "/tools/report.py";
  if (!std::filesystem::exists(script)) throw sphdisk::UserError("report script '" + script + "' not found");
  // The binary itself: a blast wave's report takes its similarity solution from `sphdisk analyze`.
  const std::string self = std::filesystem::read_symlink("/proc/self/exe", ec).string();
  const std::string cmd = "/usr/bin/python3 '" + script + "' '" + dir + "'" + (self.empty() ? "" : " --sphdisk '" + self + "'");
  const int rc = std::system(cmd.c_str());
  return rc == 0 ? 0 : 2;
}

}  // namespace

// Prints the one-line error and leaves without running library teardown: after a failed write (full
// disk) HDF5 1.10 keeps the half-closed file in its tables and crashes in its atexit handler.
// Under MPI, ranks other than 0 only report errors of their own (every rank meets the same input
// errors; rank 0 reports those), and a failing rank stops all others, which would otherwise wait
// for it forever. Such a rank first gives rank 0 a moment to report an input error and stop them
// all: stopping at once, it could kill rank 0 before its line was out (seen under load with a
// repeated ID across ranks: exit 2, no message); if it is still running after that, the error was
// its own, and it reports it. A rank told of another's error (PeerError) waits the same moment, so
// that rank 0's line is out before anything stops it.
[[noreturn]] static void exit_after_error(int code, const char* kind, const std::string& what, bool quiet = false) {
  const sphdisk::Communicator world = sphdisk::Communicator::world();
  bool own = world.is_root() || code != 2;
  if (!own && world.size() > 1) {
    std::this_thread::sleep_for(std::chrono::seconds(3));
    own = !quiet;  // a peer of rank 0's error (PeerError) has nothing of its own to say
  }
  if (!quiet && own) {
    sphdisk::run_log::write("sphdisk: " + std::string(kind) + ": " + sphdisk::one_line(what) + "\n");
    if (world.size() > 1)
      std::fprintf(stderr, "sphdisk (rank %d): %s: %s\n", world.rank(), kind, sphdisk::one_line(what).c_str());
    else
      std::fprintf(stderr, "sphdisk: %s: %s\n", kind, sphdisk::one_line(what).c_str());
  }
  std::fflush(nullptr);
  if (world.size() > 1) sphdisk::abort_all_ranks(code);
  std::_Exit(code);
}

namespace {

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// "; did you mean 'X'?" for the first word of the command line that is neither a subcommand nor
// an option of the chosen one but lies within two edits of one; "" otherwise.
std::string closest_word(const CLI::App& app, int argc, char** argv) {
  const auto closest = [](const std::string& word, const std::vector<std::string>& known) -> std::string {
    std::string best;
    std::size_t best_d = 3;
    for (const std::string& k : known) {
      if (k == word) return "";
      const std::size_t d = sphdisk::edit_distance(word, k);
      if (d < best_d) best_d = d, best = k;
    }
    return best.empty() ? "" : "; did you mean '" + best + "'?";
  };
  const CLI::App* sub = nullptr;
  for (int k = 1; k < argc; ++k) {
    const std::string word = argv[k];
    if (!sub && word.rfind('-', 0) != 0) {
      std::vector<std::string> names;
      for (const CLI::App* s : app.get_subcommands({})) {
        names.push_back(s->get_name());
        if (s->get_name() == word) sub = s;
      }
      if (!sub) return closest(word, names);
    } else if (sub && word.rfind("--", 0) == 0) {
      std::vector<std::string> names;
      for (const CLI::Option* o : sub->get_options())
        for (const std::string& l : o->get_lnames()) names.push_back("--" + l);
      const std::string hint = closest(word.substr(0, word.find('=')), names);
      if (!hint.empty()) return hint;
    }
  }
  return "";
}

// A validator of whole numbers in [lo, hi], saying which of the two a value is not.
CLI::Validator whole_number(long lo, long hi) {
  return CLI::Validator(
      [lo, hi](std::string& v) -> std::string {
        char* end = nullptr;
        errno = 0;
        const long x = std::strtol(v.c_str(), &end, 10);
        if (v.empty() || *end != '\0' || errno != 0) return "'" + v + "' is not a whole number";
        if (x < lo || x > hi) return v + " is not in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
        return "";
      },
      "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

// The first word of the command line that is not an option, where it names no command; "" otherwise.
std::string unknown_command(const CLI::App& app, int argc, char** argv) {
  for (int k = 1; k < argc; ++k) {
    const std::string word = argv[k];
    if (word.rfind('-', 0) == 0) continue;
    for (const CLI::App* s : app.get_subcommands({}))
      if (s->get_name() == word) return "";
    return word;
  }
  return "";
}

// The one line of a command-line mistake: what is wrong, then the closest command or option, or
// where no command was recognised, the commands there are.
std::string command_line_error(const CLI::App& app, int argc, char** argv, const CLI::ParseError& e) {
  const std::string unknown = unknown_command(app, argc, argv);
  std::string line = unknown.empty() ? one_line(e.what()) : "unknown command '" + unknown + "'";
  std::string hint = closest_word(app, argc, argv);
  if (hint.empty() && (!unknown.empty() || line.find("subcommand") != std::string::npos)) {
    hint = "; the commands are";
    for (const CLI::App* s : app.get_subcommands({})) hint += " " + s->get_name();
    hint += " (sphdisk --help)";
  }
  return line + hint;
}

// The command as typed, a word quoted for the shell where it needs it (for run.log).
std::string command_line(int argc, char** argv) {
  const char* plain = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-+=/.,:@%";
  std::string line;
  for (int k = 0; k < argc; ++k) {
    const std::string word = argv[k];
    std::string quoted = "'";
    for (char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    line += (k ? " " : "") + (!word.empty() && word.find_first_not_of(plain) == std::string::npos ? word : quoted + "'");
  }
  return line;
}

// A --trace file is written when the run ends: a path that cannot take it is refused before the
// run starts, not after hours of it.
void check_trace_path(const std::string& path) {
  // (Only rank 0 writes it: other ranks' nodes need not see its directory.)
  if (path.empty() || !sphdisk::Communicator::world().is_root()) return;
  namespace fs = std::filesystem;
  const fs::path p(path);
  const fs::path parent = p.has_parent_path() ? p.parent_path() : fs::path(".");
  std::error_code ec;
  if (fs::is_directory(p, ec))
    throw sphdisk::UserError("--trace '" + path + "' is a directory; give a file name, e.g. --trace " + (p / "trace.json").string());
  if (!fs::is_directory(parent, ec))
    throw sphdisk::UserError("--trace '" + path + "': the directory '" + parent.string() + "' does not exist; create it or give another path");
  if (access(parent.c_str(), W_OK) != 0)
    throw sphdisk::UserError("--trace '" + path + "': the directory '" + parent.string() + "' is not writable; give another path");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"sphdisk: parallel SPH for viscous accretion discs"};
  app.set_version_flag("--version",
                       "sphdisk " + std::string(sphdisk::code_version()) + "\nbuild: " + sphdisk::build_options() +
                           "\nvector loops on this CPU: " + sphdisk::vector_isa_name(sphdisk::vector_isa()) +
                           " (chosen at run time; every path gives the same bits)",
                       "print the code version and build options, then exit");
  app.require_subcommand(1);

  std::string config_path, output_dir, trace_file, snapshot, json_path, run_dir;
  std::vector<std::string> overrides;
  bool overwrite = false, quiet = false, help_config = false, check_only = false;
  int threads = 0, bins = 50;

  CLI::App* run = app.add_subcommand("run", "run a simulation from a TOML configuration");
  run->add_option("config", config_path, "configuration file (TOML)");
  run->add_option("--set", overrides, "override a key: section.key=value (repeatable)")
      ->allow_extra_args(false);  // one value per --set, so a positional may follow
  run->add_option("--output,-o", output_dir, "output directory (overrides output.dir)");
  run->add_flag("--overwrite", overwrite, "replace the results of an earlier run in the output directory");
  run->add_option("--threads,-t", threads, "threads (overrides run.threads)")->check(whole_number(0, 4096));
  run->add_option("--trace", trace_file, "write a Chrome trace-event JSON file (opens in Perfetto)");
  run->add_flag("--quiet,-q", quiet, "no progress lines");
  run->add_flag("--help-config", help_config, "list every configuration key with its default and exit");
  run->add_flag("--check", check_only, "validate the configuration, print it resolved, and exit");

  CLI::App* resume = app.add_subcommand("resume", "continue an interrupted run from its checkpoint");
  resume->add_option("dir", run_dir, "run directory holding checkpoint.hdf5")->required();
  resume->add_option("--set", overrides, "override a key, e.g. run.threads or a longer output.tau (repeatable)")
      ->allow_extra_args(false);
  resume->add_option("--threads,-t", threads, "threads (overrides run.threads)")->check(whole_number(0, 4096));
  resume->add_option("--trace", trace_file, "write a Chrome trace-event JSON file (opens in Perfetto)");
  resume->add_flag("--quiet,-q", quiet, "no progress lines");

  CLI::App* analyze = app.add_subcommand("analyze", "compare a snapshot with its analytic solution (the ring, a blast wave) or give a disc's radial profiles");
  analyze->add_option("snapshot", snapshot, "snapshot file (HDF5)")->required();
  analyze->add_option("--json", json_path, "also write the comparison as JSON");
  analyze->add_option("--bins", bins, "number of radial bins (the ring: over 0.05-2.05 r0; a blast wave: shells to 1.5 shock radii)")->check(whole_number(1, 100000));

  std::string study_path;
  CLI::App* sweep = app.add_subcommand("sweep", "run a study of simulations spread over MPI ranks (mpirun -np P sphdisk sweep ...)");
  sweep->add_option("study", study_path, "study file (TOML: base, output, attempts, [[run]] name + set)")->required();
  sweep->add_flag("--overwrite", overwrite, "replace the results of an earlier sweep in the output directory");

  CLI::App* report = app.add_subcommand("report", "draw the figures and report of a run directory");
  report->add_option("dir", run_dir, "run directory")->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help, --version
  } catch (const CLI::ParseError& e) {
    // One line, exit code 2, and the closest command or option where a word is mistyped (as the
    // configuration's errors).
    std::cerr << "sphdisk: " << command_line_error(app, argc, argv, e) << "\n";
    return 2;
  }
  // Runs may span MPI ranks (mpirun -np P sphdisk run ...); the other commands are one process.
  std::optional<sphdisk::MpiSession> mpi;
  if (*run || *resume || *sweep) mpi.emplace(argc, argv);

  try {
    if (*run) {
      if (help_config) {
        std::cout << sphdisk::config_reference();
        return 0;
      }
      if (config_path.empty()) throw sphdisk::UserError("run needs a configuration file, e.g. sphdisk run configs/ring.toml");
      if (run->count("--output") > 0 && output_dir.empty())
        throw sphdisk::UserError("--output (-o) was given an empty directory name; give a directory, or leave the option "
                                 "out to write to output.dir");
      check_trace_path(trace_file);
      if (threads > 0) overrides.push_back("run.threads=" + std::to_string(threads));
      const sphdisk::Config cfg = sphdisk::load_config(config_path, overrides);
      if (check_only) {
        // "auto" neighbours resolve from N here; from a file, once it is read.
        const sphdisk::Config resolved =
            cfg.initial_conditions.empty() ? sphdisk::with_neighbours_resolved(cfg, static_cast<double>(cfg.particles)) : cfg;
        sphdisk::check_neighbours_fit(cfg);
        sphdisk::check_initial_conditions_file(cfg);
        std::cout << resolved.resolved_toml;
        return 0;
      }
      const sphdisk::RunOptions opts{output_dir, overwrite, trace_file, quiet, false, command_line(argc, argv)};
      const auto summary = sphdisk::run_simulation(cfg, opts);
      if (!sphdisk::Communicator::world().is_root()) return summary.interrupted ? 75 : 0;
      if (summary.interrupted) return report_interrupted(summary);
      // The accuracy table of the last output's snapshot (the README's main job ends with it); a run
      // stopped by run.max_steps has not reached it.
      const std::string path = sphdisk::snapshot_name(summary.output_dir, cfg.output_count());
      if (!summary.stopped_early && std::filesystem::exists(path) && (cfg.viscosity > 0 || !cfg.initial_conditions.empty() || cfg.problem != "ring"))
        return cmd_analyze(path, "", 50);
      return 0;
    }
    if (*resume) {
      if (threads > 0) overrides.push_back("run.threads=" + std::to_string(threads));
      check_trace_path(trace_file);
      const sphdisk::RunOptions opts{run_dir, false, trace_file, quiet, false, command_line(argc, argv)};
      const auto summary = sphdisk::resume_simulation(run_dir, opts, overrides);
      if (!sphdisk::Communicator::world().is_root()) return summary.interrupted ? 75 : 0;
      if (summary.interrupted) return report_interrupted(summary);
      return 0;
    }
    if (*sweep) {
      const auto s = sphdisk::run_sweep(study_path, overwrite, command_line(argc, argv));
      if (!sphdisk::Communicator::world().is_root()) return 0;
      std::printf("sweep: %zu runs, %zu succeeded, %zu failed%s; attempts in %s\n", s.runs, s.succeeded, s.failed,
                  s.interrupted ? ", interrupted by a signal" : "", s.csv_path.c_str());
      if (s.interrupted) return 75;
      return s.failed == 0 ? 0 : 5;
    }
    if (*analyze) return cmd_analyze(snapshot, json_path, bins);
    if (*report) return cmd_report(run_dir);
  } catch (const sphdisk::PeerError& e) {
    exit_after_error(2, "error", e.what(), true);
  } catch (const sphdisk::UserError& e) {
    exit_after_error(2, "error", e.what());
  } catch (const sphdisk::NumericalError& e) {
    exit_after_error(3, "numerical error", e.what());
  } catch (const std::exception& e) {
    exit_after_error(4, "internal error", e.what());
  }
  return 0;
}
