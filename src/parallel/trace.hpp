#pragma once
// Trace recorder for the Chrome trace-event JSON format (opens in Perfetto / chrome://tracing).
// Each thread appends complete events ("ph":"X") to its own buffer, so recording takes no lock;
// buffers are merged when the trace is written. One track per thread (tid = thread index), one
// process track per MPI rank (pid = rank).
#include <chrono>
#include <string>
#include <string_view>
#include <vector>

namespace sphdisk::par {

void trace_enable(bool on);
bool trace_enabled();
// Records one complete event on the calling thread's track; args: the members of the event's
// "args" object as JSON text (e.g. `"active":120`), shown beside the event by Perfetto, or empty.
void trace_record(std::string_view name, double begin_us, double end_us, std::string_view args = {});
// Writes all recorded events as Chrome trace JSON; returns false on I/O failure.
bool trace_write(const std::string& path);
// This process's events as JSON objects on process track `pid` (an MPI rank), times relative to
// origin_us; and a trace file from several processes' event lists.
std::string trace_events(int pid, double origin_us);
bool trace_write(const std::string& path, const std::vector<std::string>& event_lists);
double trace_now_us();

class TraceScope {
 public:
  explicit TraceScope(std::string_view name) : name_(name) {
    if (!name_.empty() && trace_enabled()) begin_ = trace_now_us();
  }
  ~TraceScope() {
    if (begin_ >= 0) trace_record(name_, begin_, trace_now_us());
  }
  TraceScope(const TraceScope&) = delete;
  TraceScope& operator=(const TraceScope&) = delete;

 private:
  std::string_view name_;
  double begin_ = -1;
};

}  // namespace sphdisk::par
