#pragma once
// Per-phase wall-clock timers (the paper's "evaluation tools", ref. 4). A phase is timed with
// ScopedPhase; totals are printed at the end of a run and saved as JSON beside the outputs. When
// tracing is on, each phase also becomes an event on the calling thread's trace track.
#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace sphdisk {

class PhaseTimers {
 public:
  void add(const std::string& phase, double seconds);
  double total(const std::string& phase) const;
  double sum() const;
  const std::vector<std::pair<std::string, double>>& phases() const { return phases_; }
  std::string table() const;  // human-readable, one phase a line with share of the total
  std::string json() const;

 private:
  std::vector<std::pair<std::string, double>> phases_;  // in first-use order
};

class ScopedPhase {
 public:
  ScopedPhase(PhaseTimers& timers, std::string phase);
  ~ScopedPhase();
  ScopedPhase(const ScopedPhase&) = delete;
  ScopedPhase& operator=(const ScopedPhase&) = delete;

 private:
  PhaseTimers& timers_;
  std::string phase_;
  std::chrono::steady_clock::time_point start_;
  double trace_start_us_;
};

}  // namespace sphdisk
