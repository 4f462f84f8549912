#pragma once
// The portable parallel layer: the ONLY code that knows about threads. Physics code calls these
// loops with a per-particle function; whether they run serially or on OpenMP threads is decided
// here (the paper's DTS idea, sec. 2: physicists write the physics once).
//
// Determinism: every loop body writes only its own element, and reductions combine fixed-size
// blocks in block order, so results are bit-identical for any thread count.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstring>
#include <memory>
#include <span>
#include <type_traits>
#include <string_view>
#include <thread>
#include <vector>

#include "core/overwrite_vector.hpp"
#include "parallel/trace.hpp"

#ifdef SPHDISK_HAVE_OPENMP
#include <omp.h>
#endif

namespace sphdisk::par {

int max_threads();
void set_threads(int n);  // n <= 0: use the runtime default
// CPUs this process may run on (its affinity mask: an MPI launcher may have bound it to fewer
// cores than it has threads).
int cpus_available();
int thread_index();

// Loop over [0, n) with dynamic load balancing: chunks of `grain` iterations are handed out on
// demand, as particles near the ring centre have more neighbours than those in the wings. Loops
// over a few large work items (blocks) pass grain = 1.
template <class F>
void for_each(std::size_t n, F&& f, std::string_view trace_label = {}, int grain = 256) {
  const long long nn = static_cast<long long>(n);
#ifdef SPHDISK_HAVE_OPENMP
#pragma omp parallel
  {
    TraceScope scope(trace_label);
#pragma omp for schedule(dynamic, grain)
    for (long long i = 0; i < nn; ++i) f(static_cast<std::size_t>(i));
  }
#else
  (void)grain;
  TraceScope scope(trace_label);
  for (long long i = 0; i < nn; ++i) f(static_cast<std::size_t>(i));
#endif
}

// v[to(k)] = old v[from[k]] for k < from.size() (to: a permutation of the positions in from),
// through `scratch` (at least from.size() * sizeof(T) bytes), both copies in parallel.
template <class T, class A, class Index, class To>
void move_values_through(std::vector<T, A>& v, const std::vector<Index>& from, To&& to, std::span<std::byte> scratch,
                         std::string_view trace_label) {
  static_assert(std::is_trivially_copyable_v<T>, "values are moved as bytes");
  std::byte* at = scratch.data();
  for_each(from.size(), [&](std::size_t k) { std::memcpy(at + k * sizeof(T), &v[from[k]], sizeof(T)); }, trace_label, 4096);
  for_each(from.size(), [&](std::size_t k) { std::memcpy(&v[to(k)], at + k * sizeof(T), sizeof(T)); }, trace_label, 4096);
}

// The same through a scratch of its own. The moved values pass through raw memory: a std::vector<T>
// of them would first be zero-filled, on this thread alone; through an UnsetVector, so that the tens
// of MiB a block cycle's sorts move at a time lie on huge pages (core/large_allocations.hpp), not on
// thousands of fresh 4 KiB pages each faulted in. (Moving them a word at a time would hold 8 bytes
// per value rather than a tensor's 32, but slows the block integrator's sorts, and the sorts do not
// lie at the rescan mode's peak memory: docs/performance.md, "Memory per particle".)
template <class T, class A, class Index, class To>
void move_values_to(std::vector<T, A>& v, const std::vector<Index>& from, To&& to, std::string_view trace_label) {
  UnsetVector<std::byte> moved(from.size() * sizeof(T));
  move_values_through(v, from, std::forward<To>(to), moved, trace_label);
}

// v[k] = old v[order[k]] for k < order.size(); the rest of v is left as it is (order: a permutation
// of 0 .. order.size() - 1, so a prefix is rearranged in place of a whole copy).
template <class T, class A, class Index>
void permute_prefix(std::vector<T, A>& v, const std::vector<Index>& order, std::string_view trace_label = {}) {
  move_values_to(v, order, [](std::size_t k) { return k; }, trace_label);
}
// The same through a given scratch (at least order.size() * sizeof(T) bytes): one scratch serves every
// field of the run's reorder, which then allocates, zero-fills and faults in no field afresh.
template <class T, class A, class Index>
void permute_prefix(std::vector<T, A>& v, const std::vector<Index>& order, std::span<std::byte> scratch,
                    std::string_view trace_label = {}) {
  move_values_through(v, order, [](std::size_t k) { return k; }, scratch, trace_label);
}

// v[to[k]] = old v[from[k]] for every k (to: a permutation of the positions in from).
template <class T, class A, class Index>
void move_values(std::vector<T, A>& v, const std::vector<Index>& from, const std::vector<Index>& to,
                 std::string_view trace_label = {}) {
  move_values_to(v, from, [&to](std::size_t k) { return to[k]; }, trace_label);
}

// offsets[0] = 0, offsets[k + 1] = offsets[k] + count(k) for k < n (offsets gets n + 1 entries): sums
// of blocks of counts in parallel, the blocks' starts serially, then every offset in parallel.
// Integer sums, so the same values for any thread count.
template <class Offsets, class Count>
void prefix_offsets(std::size_t n, Count&& count, Offsets& offsets, std::string_view trace_label = {}) {
  constexpr std::size_t kBlock = 4096;
  const std::size_t nblocks = (n + kBlock - 1) / kBlock;
  offsets.resize(n + 1);
  std::vector<std::size_t> start(nblocks + 1, 0);
  for_each(nblocks, [&](std::size_t b) {
    std::size_t sum = 0;
    for (std::size_t k = b * kBlock, end = std::min(n, k + kBlock); k < end; ++k) sum += count(k);
    start[b + 1] = sum;
  }, trace_label, 1);
  for (std::size_t b = 0; b < nblocks; ++b) start[b + 1] += start[b];
  offsets[0] = 0;
  for_each(nblocks, [&](std::size_t b) {
    std::size_t at = start[b];
    for (std::size_t k = b * kBlock, end = std::min(n, k + kBlock); k < end; ++k) {
      at += count(k);
      offsets[k + 1] = static_cast<typename Offsets::value_type>(at);
    }
  }, trace_label, 1);
}

// Coloured work items: colour c holds items [colour_start[c], colour_start[c + 1]). Colours run one
// after the other; the items of one colour run in parallel (dynamically balanced), so items that
// write to common data must get different colours (neighbours/pair_lists.hpp).
template <class F>
void for_each_coloured(const std::vector<std::size_t>& colour_start, F&& f, std::string_view trace_label = {}) {
  for (std::size_t c = 0; c + 1 < colour_start.size(); ++c) {
    const std::size_t first = colour_start[c];
    for_each(colour_start[c + 1] - first, [&](std::size_t k) { f(first + k); }, trace_label, 1);
  }
}

// Jobs [0, n) that may run only after some earlier ones: depends(k, need) calls need(j) for each
// job j < k that must have finished before job k starts. A thread takes the first job, among the
// next kJobWindow not yet taken, whose dependencies have finished (one that waited would hold its
// thread idle: the next job often depends on the one just taken). With dependencies that join
// every two jobs writing to common data, each datum sees its writes in job order for any thread
// count. No deadlock: only ready jobs are taken, and the earliest job not taken becomes ready once
// the running jobs finish. Unlike colours, no barrier holds all threads until the slowest job of
// a colour ends.
inline constexpr std::size_t kJobWindow = 32;

template <class Depends, class F>
void for_each_after(std::size_t n, Depends&& depends, F&& f, std::string_view trace_label = {}) {
  if (n == 0) return;
  const auto done = std::make_unique<std::atomic<unsigned char>[]>(n);
  const auto taken = std::make_unique<std::atomic<unsigned char>[]>(n);
  for (std::size_t k = 0; k < n; ++k) {
    done[k].store(0, std::memory_order_relaxed);
    taken[k].store(0, std::memory_order_relaxed);
  }
  std::atomic<std::size_t> first_open{0};  // every job before it is taken
  std::atomic<std::size_t> finished{0};
  const auto ready = [&](std::size_t k) {
    bool yes = true;
    depends(k, [&](std::size_t j) { yes = yes && done[j].load(std::memory_order_acquire); });
    return yes;
  };
  const auto work = [&] {
    TraceScope scope(trace_label);
    for (unsigned idle = 0; finished.load(std::memory_order_acquire) < n;) {
      std::size_t k = first_open.load(std::memory_order_acquire);
      const std::size_t end = std::min(n, k + kJobWindow);
      for (; k < end; ++k) {
        if (taken[k].load(std::memory_order_relaxed) || !ready(k)) continue;
        unsigned char expected = 0;
        if (taken[k].compare_exchange_strong(expected, 1, std::memory_order_acq_rel)) break;
      }
      if (k == end) {  // nothing ready: wait for a running job
        if (++idle > 4096) std::this_thread::yield();
        continue;
      }
      idle = 0;
      // Move the front past the jobs taken (any thread may; it only grows).
      for (std::size_t open = first_open.load(std::memory_order_acquire);
           open < n && taken[open].load(std::memory_order_acquire);) {
        if (first_open.compare_exchange_weak(open, open + 1, std::memory_order_acq_rel)) ++open;
      }
      f(k);
      done[k].store(1, std::memory_order_release);
      finished.fetch_add(1, std::memory_order_acq_rel);
    }
  };
#ifdef SPHDISK_HAVE_OPENMP
#pragma omp parallel
  work();
#else
  work();
#endif
}

// Deterministic reduction: blocks of kBlock elements are reduced in index order, then the block
// partials are combined serially in block order. Same bits for any thread count.
inline constexpr std::size_t kReduceBlock = 4096;

template <class T, class F, class Op>
T reduce(std::size_t n, T init, F&& f, Op&& op) {
  const std::size_t nblocks = (n + kReduceBlock - 1) / kReduceBlock;
  std::vector<T> partial(nblocks, init);
  for_each(nblocks, [&](std::size_t b) {
    T acc = init;
    const std::size_t end = std::min(n, (b + 1) * kReduceBlock);
    for (std::size_t i = b * kReduceBlock; i < end; ++i) acc = op(acc, f(i));
    partial[b] = acc;
  }, {}, 1);
  T total = init;
  for (const T& p : partial) total = op(total, p);
  return total;
}

template <class T, class F>
T sum(std::size_t n, F&& f) {
  return reduce(n, T{}, std::forward<F>(f), [](const T& a, const T& b) { return a + b; });
}

// Functional fork/join: each task reads its inputs and returns its result; results come back in
// task order whatever thread ran them (no shared mutable state).
template <class R, class F>
std::vector<R> map_tasks(std::size_t ntasks, F&& task) {
  std::vector<R> out(ntasks);
#ifdef SPHDISK_HAVE_OPENMP
#pragma omp parallel
#pragma omp single
  for (std::size_t t = 0; t < ntasks; ++t) {
#pragma omp task firstprivate(t) shared(out, task)
    out[t] = task(t);
  }
#else
  for (std::size_t t = 0; t < ntasks; ++t) out[t] = task(t);
#endif
  return out;
}

}  // namespace sphdisk::par
