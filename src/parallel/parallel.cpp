// Thread control and trace buffers of the parallel layer.
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <iomanip>
#include <mutex>
#include <sstream>
#include <vector>

#include "parallel/loops.hpp"

namespace sphdisk::par {

int max_threads() {
#ifdef SPHDISK_HAVE_OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

void set_threads(int n) {
#ifdef SPHDISK_HAVE_OPENMP
  static const int runtime_default = omp_get_max_threads();  // OMP_NUM_THREADS or the core count
  omp_set_num_threads(n > 0 ? n : runtime_default);
#else
  (void)n;
#endif
}

int cpus_available() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) != 0) return max_threads();  // unknown: assume enough
  return CPU_COUNT(&set);
}

int thread_index() {
#ifdef SPHDISK_HAVE_OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

namespace {
struct Event {
  std::string name;
  double begin_us, end_us;
  int tid;
  std::string args;  // JSON members of "args", or empty
};
std::atomic<bool> g_enabled{false};
std::mutex g_buffers_mutex;                     // guards the list of buffers, not the hot path
std::vector<std::vector<Event>*> g_buffers;     // one per thread that ever recorded
const auto g_epoch = std::chrono::steady_clock::now();

std::vector<Event>& thread_buffer() {
  thread_local std::vector<Event>* buf = [] {
    auto* b = new std::vector<Event>();  // lives until exit: threads of the OpenMP pool persist
    std::lock_guard<std::mutex> lock(g_buffers_mutex);
    g_buffers.push_back(b);
    return b;
  }();
  return *buf;
}

void json_escape(std::ostream& os, const std::string& s) {
  for (char c : s) {
    if (c == '"' || c == '\\') os << '\\';
    os << c;
  }
}
}  // namespace

void trace_enable(bool on) { g_enabled = on; }
bool trace_enabled() { return g_enabled.load(std::memory_order_relaxed); }
double trace_now_us() {
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - g_epoch).count();
}
void trace_record(std::string_view name, double begin_us, double end_us, std::string_view args) {
  thread_buffer().push_back(Event{std::string(name), begin_us, end_us, thread_index(), std::string(args)});
}

std::string trace_events(int pid, double origin_us) {
  std::ostringstream os;
  // Microseconds to the nanosecond, in fixed notation: the stream's default 6 significant digits
  // would round a time stamp 100 s into a run to 100 us and misplace events against each other.
  os << std::fixed << std::setprecision(3);
  bool first = true;
  std::lock_guard<std::mutex> lock(g_buffers_mutex);
  for (const auto* buf : g_buffers) {
    for (const Event& e : *buf) {
      if (!first) os << ",\n";
      first = false;
      os << "{\"name\":\"";
      json_escape(os, e.name);
      os << "\",\"ph\":\"X\",\"pid\":" << pid << ",\"tid\":" << e.tid << ",\"ts\":" << e.begin_us - origin_us
         << ",\"dur\":" << (e.end_us - e.begin_us);
      if (!e.args.empty()) os << ",\"args\":{" << e.args << "}";
      os << "}";
    }
  }
  return os.str();
}

bool trace_write(const std::string& path, const std::vector<std::string>& event_lists) {
  std::ofstream os(path);
  if (!os) return false;
  os << "{\"displayTimeUnit\":\"ms\",\"traceEvents\":[\n";
  bool first = true;
  for (const std::string& events : event_lists) {
    if (events.empty()) continue;
    if (!first) os << ",\n";
    first = false;
    os << events;
  }
  os << "\n]}\n";
  return static_cast<bool>(os);
}

bool trace_write(const std::string& path) { return trace_write(path, {trace_events(0, 0.0)}); }

}  // namespace sphdisk::par
