#pragma once
// `sphdisk sweep STUDY.toml`: a set of simulations (e.g. the paper's particle numbers and integrator
// tolerances) spread over the MPI ranks as remote tasks (parallel/task_farm.hpp): each idle rank takes
// the next run, a run that fails is retried on another rank. Every run is a one-process simulation
// with its own output directory; rank 0 writes OUTPUT/sweep.csv with one row per attempt.
//
// Study file:
//   base = "configs/ring.toml"   # configuration every run starts from (relative to the study file)
//   output = "runs/sweep"        # run NAME writes to OUTPUT/NAME
//   attempts = 2                 # tries per run (optional, default 2)
//   [[run]]
//   name = "N10000"
//   set = ["problem.particles=10000", "output.tau=[0.036]"]
#include <string>

namespace sphdisk {

struct SweepSummary {
  std::size_t runs = 0, succeeded = 0, failed = 0;
  bool interrupted = false;  // a signal stopped the study (runs not started are not counted)
  std::string csv_path;
};

// Collective over MPI ranks. All run configurations are checked before any run starts (UserError).
// `command_line` heads each run's run.log.
SweepSummary run_sweep(const std::string& study_path, bool overwrite, const std::string& command_line = "");

}  // namespace sphdisk
