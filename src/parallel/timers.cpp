#include "parallel/timers.hpp"

#include <cstdio>
#include <sstream>

#include "parallel/trace.hpp"

namespace sphdisk {

void PhaseTimers::add(const std::string& phase, double seconds) {
  for (auto& [name, t] : phases_)
    if (name == phase) {
      t += seconds;
      return;
    }
  phases_.emplace_back(phase, seconds);
}

double PhaseTimers::total(const std::string& phase) const {
  for (const auto& [name, t] : phases_)
    if (name == phase) return t;
  return 0.0;
}

double PhaseTimers::sum() const {
  double s = 0;
  for (const auto& p : phases_) s += p.second;
  return s;
}

std::string PhaseTimers::table() const {
  std::ostringstream os;
  const double all = sum();
  char line[128];
  for (const auto& [name, t] : phases_) {
    std::snprintf(line, sizeof line, "  %-20s %10.3f s  %5.1f %%\n", name.c_str(), t,
                  all > 0 ? 100.0 * t / all : 0.0);
    os << line;
  }
  std::snprintf(line, sizeof line, "  %-20s %10.3f s\n", "total", all);
  os << line;
  return os.str();
}

std::string PhaseTimers::json() const {
  std::ostringstream os;
  os.precision(9);
  os << "{";
  for (std::size_t k = 0; k < phases_.size(); ++k)
    os << (k ? ", " : "") << '"' << phases_[k].first << "\": " << phases_[k].second;
  os << "}\n";
  return os.str();
}

ScopedPhase::ScopedPhase(PhaseTimers& timers, std::string phase)
    : timers_(timers), phase_(std::move(phase)), start_(std::chrono::steady_clock::now()),
      trace_start_us_(par::trace_enabled() ? par::trace_now_us() : -1) {}

ScopedPhase::~ScopedPhase() {
  timers_.add(phase_, std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
  if (trace_start_us_ >= 0) par::trace_record(phase_, trace_start_us_, par::trace_now_us());
}

}  // namespace sphdisk
