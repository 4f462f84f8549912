#pragma once
// Remote tasks, the distributed half of the paper's DTS (P98 sec. 2.1, Fig. 1): functional tasks that
// run on other ranks. A manager on rank 0 hands each idle rank the next task as soon as it asks, so
// the load balances itself (ranks that finish early get more); a task's result goes straight back
// to the manager; a task whose executor fails (throws) is reported and re-queued, preferably on
// another rank, up to `attempts` times. With one rank, rank 0 runs every task itself.
#include <functional>
#include <string>

#include "parallel/communicator.hpp"

namespace sphdisk {

struct TaskOutcome {
  bool ok = false;
  std::string message;   // the result (ok) or the failure
  double seconds = 0;    // the executor's wall time
  bool stop_all = false; // not ok and no more tasks anywhere (e.g. the user interrupted the study)
};

struct TaskReport {
  std::size_t task = 0;
  int rank = 0;          // where it ran
  int attempt = 1;       // 1, 2, ...
  TaskOutcome outcome;
  bool final = false;    // no further attempt follows (it succeeded or ran out of attempts)
};

// Collective: every rank calls it with the same n_tasks and attempts. execute(task) runs on the
// worker ranks (on rank 0 too when it is the only rank) and returns the outcome (an exception is a
// failed outcome). on_report runs on rank 0 for every attempt, in the order results arrive. Once
// stop_requested() (asked on rank 0 before each hand-out) is true, no further task starts.
void run_task_farm(const Communicator& comm, std::size_t n_tasks, int attempts,
                   const std::function<TaskOutcome(std::size_t task)>& execute,
                   const std::function<void(const TaskReport&)>& on_report,
                   const std::function<bool()>& stop_requested = [] { return false; });

}  // namespace sphdisk
