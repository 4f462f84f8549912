#pragma once
// The simulation driver: sets up the run, then advances it step by step, writing snapshots at
// the requested viscous times, a diagnostics row per step and a progress line with ETA.
#include <string>
#include <vector>

#include "core/config.hpp"

namespace sphdisk {

struct RunOptions {
  std::string output_dir;   // overrides output.dir when not empty
  bool overwrite = false;   // allow replacing outputs of an earlier run in the same directory
  std::string trace_file;   // Chrome trace JSON, "" for none
  bool quiet = false;       // no progress lines
  bool one_process = false; // this rank alone, even under mpirun (a run of a sweep)
  std::string command_line; // the command as typed, for run.log
};

struct RunSummary {
  long long steps = 0;
  std::size_t evaluations = 0;
  std::size_t particles_final = 0;
  double wall_seconds = 0;
  double particle_updates_per_second = 0;  // particles x rate evaluations / wall time
  std::string output_dir;
  bool interrupted = false;  // stopped by SIGTERM/SIGINT after writing a checkpoint, or (abandoned) without
  bool abandoned = false;    // stopped by a second signal inside a step, which was not saved
  bool stopped_early = false;  // stopped by run.max_steps before the last output time
  long long checkpoint_step = -1;  // the step of the run's last checkpoint (-1: none yet)
  bool checkpoint_inside_step = false;  // that checkpoint was written inside the next step's block cycle
};

// What an interrupted run tells its user: where it stopped and how to continue.
std::string interruption_note(const RunSummary& s);

RunSummary run_simulation(const Config& cfg, const RunOptions& opts);

// Refuses a problem.initial_conditions that names no file (before a run, and for run --check).
void check_initial_conditions_file(const Config& cfg);

// Continues the run in `dir` from its checkpoint.hdf5 (same configuration; `overrides` may change
// e.g. run.threads or extend output.tau). Any thread count gives the same bits.
RunSummary resume_simulation(const std::string& dir, const RunOptions& opts, const std::vector<std::string>& overrides);

}  // namespace sphdisk
