#include "app/sweep.hpp"

#include <csignal>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include "app/run_directory.hpp"
#include "app/run_log.hpp"
#include "app/simulation.hpp"
#include "core/config.hpp"
#include "core/error.hpp"
#include "core/toml.hpp"
#include "io/atomic_file.hpp"
#include "parallel/task_farm.hpp"

namespace sphdisk {

namespace fs = std::filesystem;

namespace {

// SIGTERM / SIGINT during a study (a batch job's time limit) while no run of this process is
// active: counted, so that no further run starts and sweep.csv is kept; a run that is active
// takes the signal itself (app/runner.cpp) and stops at its checkpoint.
volatile std::sig_atomic_t g_sweep_stop_signals = 0;
extern "C" void on_sweep_stop_signal(int) { g_sweep_stop_signals = g_sweep_stop_signals + 1; }

struct SweepRun {
  std::string name;
  std::vector<std::string> overrides;
};

struct Study {
  std::string base;    // path of the base configuration
  std::string output;  // directory of the runs
  int attempts = 2;
  std::vector<SweepRun> runs;
};

std::string csv_field(std::string s) {
  for (char& c : s)
    if (c == '"' || c == '\n' || c == '\r') c = '\'';
  return "\"" + s + "\"";
}

Study read_study(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw UserError("'" + path + "' is a directory, not a study file; give a TOML study file");
  std::ifstream in(path);
  if (!in) throw UserError("cannot read study file '" + path + "'; give an existing TOML file");
  std::stringstream text;
  text << in.rdbuf();
  toml::table t;
  try {
    t = toml::parse(text.str(), path);
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    throw UserError(path + ":" + std::to_string(b.line) + ":" + std::to_string(b.column) + ": invalid TOML: " +
                    one_line(std::string(e.description())));
  }
  for (const auto& [key, node] : t)
    if (key != "base" && key != "output" && key != "attempts" && key != "run")
      throw UserError(path + ": unknown key '" + std::string(key.str()) + "'; allowed: base, output, attempts, [[run]]");
  Study s;
  const auto base = t["base"].value<std::string>();
  if (!base) throw UserError(path + ": 'base' (the configuration every run starts from) is missing or not a string");
  s.base = (fs::path(path).parent_path() / *base).lexically_normal().string();
  s.output = t["output"].value_or(std::string("runs/sweep"));
  const auto attempts = t["attempts"].value_or(std::int64_t{2});
  if (attempts < 1 || attempts > 10) throw UserError(path + ": attempts must be in [1, 10]");
  s.attempts = static_cast<int>(attempts);
  const toml::array* runs = t["run"].as_array();
  if (!runs || runs->empty()) throw UserError(path + ": no [[run]] tables; add at least one with a name");
  std::set<std::string> names;
  for (const toml::node& node : *runs) {
    const toml::table* r = node.as_table();
    if (!r) throw UserError(path + ": every [[run]] must be a table");
    SweepRun run;
    run.name = (*r)["name"].value_or(std::string());
    // (A name of dots alone would name the output directory or its parent, not a run's own.)
    if (run.name.empty() || run.name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.-") != std::string::npos ||
        run.name.find_first_not_of('.') == std::string::npos)
      throw UserError(path + ": run name '" + run.name + "' must use only letters, digits, _ . - and not be dots alone");
    if (!names.insert(run.name).second) throw UserError(path + ": run name '" + run.name + "' appears twice");
    for (const auto& [key, value] : *r)
      if (key != "name" && key != "set")
        throw UserError(path + ": unknown key '" + std::string(key.str()) + "' in run '" + run.name + "'; allowed: name, set");
    const std::string set_form = ": run '" + run.name + "': 'set' must be a list of \"section.key=value\" strings";
    if (r->contains("set") && !(*r)["set"].as_array()) throw UserError(path + set_form + " (in brackets, even for one)");
    if (const toml::array* set = (*r)["set"].as_array())
      for (const toml::node& o : *set) {
        const auto v = o.value<std::string>();
        if (!v) throw UserError(path + set_form);
        run.overrides.push_back(*v);
      }
    s.runs.push_back(std::move(run));
  }
  return s;
}

}  // namespace

SweepSummary run_sweep(const std::string& study_path, bool overwrite, const std::string& command_line) {
  const Study study = read_study(study_path);
  // Every run's configuration is checked here, on every rank, before any run starts.
  std::vector<Config> configs;
  for (const SweepRun& r : study.runs) {
    try {
      configs.push_back(load_config(study.base, r.overrides));
      // (the run's own checks, made here for every run before any starts)
      check_neighbours_fit(configs.back());
      check_initial_conditions_file(configs.back());
    } catch (const UserError& e) {
      throw UserError("run '" + r.name + "': " + e.what());
    }
  }
  const Communicator comm = Communicator::world();
  SweepSummary summary;
  summary.runs = study.runs.size();
  summary.csv_path = (fs::path(study.output) / "sweep.csv").string();
  std::ostringstream csv;
  csv << "run,status,rank,attempt,wall_seconds,message\n";
  // Results of an earlier sweep are kept unless asked (each attempt then writes over its run's
  // directory, so a retry replaces what a failed attempt left).
  run_on_root(comm, [&] {
    std::error_code ec;
    fs::create_directories(study.output, ec);
    if (ec) throw UserError("cannot create sweep output directory '" + study.output + "': " + ec.message());
    for (const SweepRun& r : study.runs)
      if (!overwrite && fs::exists(fs::path(study.output) / r.name / kDiagnosticsName))
        throw UserError("sweep output '" + (fs::path(study.output) / r.name).string() +
                        "' already holds results; use another output, or --overwrite to replace them");
  });
  g_sweep_stop_signals = 0;
  auto old_term = std::signal(SIGTERM, on_sweep_stop_signal);
  auto old_int = std::signal(SIGINT, on_sweep_stop_signal);
  run_task_farm(
      comm, study.runs.size(), study.attempts,
      [&](std::size_t k) {
        RunOptions opts;
        opts.output_dir = (fs::path(study.output) / study.runs[k].name).string();
        opts.overwrite = true;  // checked above; a retried attempt replaces what the failed one left
        opts.quiet = true;
        opts.one_process = true;
        opts.command_line = command_line + "  (run " + study.runs[k].name + " of the study)";
        RunSummary s;
        try {
          s = run_simulation(configs[k], opts);
        } catch (const std::exception& e) {  // the failure goes into the run's log too
          run_log::write("sphdisk: run failed: " + one_line(e.what()) + "\n");
          run_log::close();
          throw;
        }
        run_log::close();
        if (s.interrupted)  // SIGTERM/SIGINT: the study stops; this run can be resumed
          return TaskOutcome{false, interruption_note(s), 0.0, true};
        return TaskOutcome{true, std::to_string(s.steps) + " steps", 0.0};
      },
      [&](const TaskReport& r) {
        const bool ok = r.outcome.ok;
        if (r.final) ++(ok ? summary.succeeded : summary.failed);
        summary.interrupted = summary.interrupted || r.outcome.stop_all;
        csv << study.runs[r.task].name << ',' << (ok ? "ok" : (r.final ? "failed" : "retried")) << ',' << r.rank << ','
            << r.attempt << ',' << r.outcome.seconds << ',' << csv_field(one_line(r.outcome.message)) << '\n';
        std::fprintf(stderr, "sweep: %s on rank %d (attempt %d): %s%s\n", study.runs[r.task].name.c_str(), r.rank,
                     r.attempt, ok ? "ok, " : "FAILED: ", one_line(r.outcome.message).c_str());
        write_text_atomically(summary.csv_path, csv.str());  // after each attempt: a stopped study keeps its rows
      },
      [] { return g_sweep_stop_signals > 0; });
  std::signal(SIGTERM, old_term);
  std::signal(SIGINT, old_int);
  summary.interrupted = summary.interrupted || g_sweep_stop_signals > 0;
  if (comm.is_root()) write_text_atomically(summary.csv_path, csv.str());
  return summary;
}

}  // namespace sphdisk
