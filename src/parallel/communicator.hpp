#pragma once
// The distributed half of the parallel layer: the ONLY code that knows about MPI (loops.hpp is the
// only code that knows about threads). Built without MPI (SPHDISK_MPI=OFF) it is a communicator of
// one rank, so every caller is written once for any number of ranks.
//
// Determinism: reductions offered here are exact (min, max, integer sums), so every rank gets the
// same bits whatever the rank count; floating-point sums, whose bits depend on the order, are
// deliberately not offered.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace sphdisk {

// What this process has sent so far, counted where it goes through a Communicator (the inputs of
// a communication-cost model; counting only, no effect on what is sent). Exchanges: personalised
// all-to-alls, each with one all-to-all of byte counts first, and all_to_all of one value per rank
// (which counts as such an opening alone); messages and bytes: the exchanges' non-empty buffers
// to other ranks. Reductions: all-reduces, gather_values, barriers and `any`,
// with their payload bytes per rank. Point-to-point sends count as messages of their own.
struct Traffic {
  std::uint64_t exchanges = 0, messages = 0, bytes = 0, reductions = 0, reduction_bytes = 0;
  Traffic& operator+=(const Traffic& o);
  Traffic operator-(const Traffic& o) const;
};

// Everything this process has sent since it started (zero on one rank: nothing is sent).
Traffic sent_traffic();

class Communicator {
 public:
  // All ranks of the run (one rank when MPI was not started: see MpiSession).
  static Communicator world();
  // This rank alone (a one-process simulation inside a distributed sweep).
  static Communicator self() { return Communicator(0, 1, nullptr); }

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool is_root() const { return rank_ == 0; }

  double min(double x) const;
  double max(double x) const;
  std::uint64_t sum(std::uint64_t x) const;
  // Element-wise over all ranks, in place.
  void min(std::span<double> x) const;
  void max(std::span<double> x) const;
  void max(std::span<std::uint64_t> x) const;
  void sum(std::span<std::uint64_t> x) const;
  // Sum of one value per rank, added in rank order on every rank: the same bits on every rank for a
  // given rank count, but not across rank counts (for diagnostics, never for particle state).
  double sum_in_rank_order(double x) const;
  // Every rank's bytes on every rank, by rank.
  std::vector<std::vector<std::byte>> all_gather(const std::vector<std::byte>& mine) const;
  // Every rank's values on every rank, rank after rank (as many from each rank: one collective of
  // log P latencies, where all_gather is a personalised exchange of P messages).
  std::vector<double> gather_values(std::span<const double> mine) const;
  // Every rank's text on rank 0, by rank (empty elsewhere).
  std::vector<std::string> gather_to_root(const std::string& mine) const;
  // True on every rank when any rank passes true (a collective decision).
  bool any(bool x) const;

  // Personalised all-to-all: send[r] goes to rank r; returns what each rank sent here, by rank.
  std::vector<std::vector<std::byte>> exchange(const std::vector<std::vector<std::byte>>& send) const;
  // The same for one value per rank (P values in and out per rank, where a sum of a P x P table
  // would carry P^2).
  std::vector<std::uint64_t> all_to_all(const std::vector<std::uint64_t>& send) const;

  void barrier() const;

  // Point to point (the task farm's requests and replies): blocking, in order between two ranks.
  void send(int to, const std::vector<std::byte>& bytes) const;
  std::vector<std::byte> receive_from(int from) const;
  std::vector<std::byte> receive_from_any(int& from) const;

  // The MPI_Comm (as MPI_Comm*) for MPI-aware libraries set up in the parallel layer (the MPI-IO
  // file driver: parallel/shared_file.cpp); null for a communicator of one rank without MPI.
  void* native_handle() const { return handle_; }

 private:
  Communicator(int rank, int size, void* handle) : rank_(rank), size_(size), handle_(handle) {}
  int rank_ = 0, size_ = 1;
  void* handle_ = nullptr;  // MPI_Comm when built with MPI
};

// Initialises MPI for the program's lifetime when the program was started by an MPI launcher
// (threads are used inside each rank: the funnelled level suffices, as only the main thread
// communicates). Started directly, the program is one process and does not touch MPI at all (an
// MPI singleton start needs shared-memory files and time; the world communicator then has one rank).
// A no-op without MPI.
class MpiSession {
 public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
};

// Runs `f` on every rank; a UserError on any rank stops every rank: rank 0 throws UserError with
// the message of the lowest failing rank, the others throw PeerError (they stop quietly: rank 0
// reports it). Collective; `f` must not call collectives after it throws.
template <class F>
void run_collectively(const Communicator& comm, F&& f) {
  std::string error;
  try {
    f();
  } catch (const UserError& e) {
    error = e.what();
  }
  if (!comm.any(!error.empty())) return;
  const std::vector<std::string> errors = comm.gather_to_root(error);
  if (!comm.is_root()) throw PeerError(error.empty() ? "another rank failed" : error);
  for (const std::string& e : errors)
    if (!e.empty()) throw UserError(e);
}

// Runs `f` on rank 0 only (files written by one process), with run_collectively's error hand-off.
template <class F>
void run_on_root(const Communicator& comm, F&& f) {
  run_collectively(comm, [&] {
    if (comm.is_root()) f();
  });
}

// Aborts every rank (a rank that fails alone would leave the others waiting forever).
[[noreturn]] void abort_all_ranks(int code);

}  // namespace sphdisk
