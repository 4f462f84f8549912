#include "parallel/task_farm.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <deque>
#include <exception>
#include <set>
#include <vector>

namespace sphdisk {

namespace {

// Worker -> manager: the finished task (or none yet) and its outcome. Manager -> worker: the next
// task, or kStop.
constexpr std::uint64_t kNone = ~std::uint64_t{0};
constexpr std::uint64_t kStop = ~std::uint64_t{0};

std::vector<std::byte> encode_result(std::uint64_t task, const TaskOutcome& o) {
  std::vector<std::byte> b(8 + 8 + 8 + o.message.size());
  const std::uint64_t ok = (o.ok ? 1 : 0) | (o.stop_all ? 2 : 0);
  std::memcpy(b.data(), &task, 8);
  std::memcpy(b.data() + 8, &ok, 8);
  std::memcpy(b.data() + 16, &o.seconds, 8);
  if (!o.message.empty()) std::memcpy(b.data() + 24, o.message.data(), o.message.size());
  return b;
}

std::uint64_t decode_result(const std::vector<std::byte>& b, TaskOutcome& o) {
  std::uint64_t task = kNone, ok = 0;
  std::memcpy(&task, b.data(), 8);
  std::memcpy(&ok, b.data() + 8, 8);
  std::memcpy(&o.seconds, b.data() + 16, 8);
  o.ok = (ok & 1) != 0;
  o.stop_all = (ok & 2) != 0;
  o.message.assign(reinterpret_cast<const char*>(b.data()) + 24, b.size() - 24);
  return task;
}

std::vector<std::byte> encode_task(std::uint64_t task) {
  std::vector<std::byte> b(8);
  std::memcpy(b.data(), &task, 8);
  return b;
}

TaskOutcome run_one(const std::function<TaskOutcome(std::size_t)>& execute, std::size_t task) {
  const auto start = std::chrono::steady_clock::now();
  TaskOutcome o;
  try {
    o = execute(task);
  } catch (const std::exception& e) {
    o.ok = false;
    o.message = e.what();
  }
  o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return o;
}

struct Pending {
  std::size_t task;
  int attempt;                 // the attempt this one will be
  std::set<int> failed_on;     // ranks where it failed before
};

}  // namespace

void run_task_farm(const Communicator& comm, std::size_t n_tasks, int attempts,
                   const std::function<TaskOutcome(std::size_t)>& execute,
                   const std::function<void(const TaskReport&)>& on_report,
                   const std::function<bool()>& stop_requested) {
  attempts = std::max(attempts, 1);
  if (comm.size() == 1) {
    for (std::size_t t = 0; t < n_tasks; ++t)
      for (int a = 1; a <= attempts; ++a) {
        if (stop_requested()) return;
        const TaskOutcome o = run_one(execute, t);
        on_report(TaskReport{t, 0, a, o, o.ok || o.stop_all || a == attempts});
        if (o.stop_all) return;
        if (o.ok) break;
      }
    return;
  }
  if (!comm.is_root()) {  // worker: ask, run, report, until told to stop
    std::vector<std::byte> msg = encode_result(kNone, TaskOutcome{});
    for (;;) {
      comm.send(0, msg);
      const std::vector<std::byte> reply = comm.receive_from(0);
      std::uint64_t task = kStop;
      std::memcpy(&task, reply.data(), 8);
      if (task == kStop) return;
      msg = encode_result(task, run_one(execute, static_cast<std::size_t>(task)));
    }
  }
  // Manager.
  std::deque<Pending> queue;
  for (std::size_t t = 0; t < n_tasks; ++t) queue.push_back(Pending{t, 1, {}});
  std::vector<Pending> running(static_cast<std::size_t>(comm.size()));
  int workers = comm.size() - 1;
  bool stopping = false;
  while (workers > 0) {
    int from = 0;
    const std::vector<std::byte> msg = comm.receive_from_any(from);
    TaskOutcome o;
    const std::uint64_t done = decode_result(msg, o);
    if (done != kNone) {
      Pending p = running[static_cast<std::size_t>(from)];
      const bool final = o.ok || o.stop_all || p.attempt >= attempts;
      on_report(TaskReport{p.task, from, p.attempt, o, final});
      stopping = stopping || o.stop_all;
      if (!final) {
        p.failed_on.insert(from);
        ++p.attempt;
        queue.push_front(p);  // retried before new tasks
      }
    }
    // The first queued task that has not failed on this rank, else the first one.
    auto next = std::find_if(queue.begin(), queue.end(), [&](const Pending& p) { return !p.failed_on.count(from); });
    if (next == queue.end()) next = queue.begin();
    stopping = stopping || stop_requested();
    if (next == queue.end() || stopping) {
      comm.send(from, encode_task(kStop));
      --workers;
      continue;
    }
    running[static_cast<std::size_t>(from)] = *next;
    comm.send(from, encode_task(next->task));
    queue.erase(next);
  }
}

}  // namespace sphdisk
