// The cost of the code's own communication between the ranks it is started on, for the scaling
// model (bench/scaling_model.py): seconds per Communicator::exchange (each rank sends `bytes` to
// every other rank) and per element-wise all-reduce (Communicator::max over `bytes` of uint64), by
// message size. A fit of t = latency + bytes / bandwidth to these gives the model's constants.
//   mpirun -np 2 -x OMP_NUM_THREADS=1 build/release/bench/comm_bench > docs/data/comm_bench_DATE.csv
// Prints "operation,ranks,bytes,seconds": the median of 7 batches of repeats, each ~20 ms.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "parallel/communicator.hpp"

namespace {
using namespace sphdisk;
using Clock = std::chrono::steady_clock;

// Seconds per call of f: the median over batches, every rank timing the same calls.
template <class F>
double seconds_per_call(const Communicator& comm, F&& f) {
  f();  // first touch of the buffers and of MPI's paths
  int reps = 1;
  for (;;) {  // repeats for a batch of ~20 ms, the same on every rank (max over ranks)
    comm.barrier();
    const auto t0 = Clock::now();
    for (int k = 0; k < reps; ++k) f();
    const double t = comm.max(std::chrono::duration<double>(Clock::now() - t0).count());
    if (t > 0.02 || reps >= (1 << 20)) break;
    reps *= 2;
  }
  std::vector<double> batches;
  for (int b = 0; b < 7; ++b) {
    comm.barrier();
    const auto t0 = Clock::now();
    for (int k = 0; k < reps; ++k) f();
    batches.push_back(comm.max(std::chrono::duration<double>(Clock::now() - t0).count()) / reps);
  }
  std::nth_element(batches.begin(), batches.begin() + 3, batches.end());
  return batches[3];
}

void exchange_row(const Communicator& comm, std::size_t bytes) {
  std::vector<std::vector<std::byte>> send(static_cast<std::size_t>(comm.size()), std::vector<std::byte>(bytes));
  send[static_cast<std::size_t>(comm.rank())].clear();
  const double t = seconds_per_call(comm, [&] { (void)comm.exchange(send); });
  if (comm.is_root()) std::printf("exchange,%d,%zu,%.9g\n", comm.size(), bytes, t);
}

void all_reduce_row(const Communicator& comm, std::size_t bytes) {
  std::vector<std::uint64_t> v(std::max<std::size_t>(bytes / 8, 1), comm.rank());
  const double t = seconds_per_call(comm, [&] { comm.max(std::span<std::uint64_t>(v)); });
  if (comm.is_root()) std::printf("all_reduce,%d,%zu,%.9g\n", comm.size(), v.size() * 8, t);
}

}  // namespace

int main(int argc, char** argv) {
  MpiSession mpi(argc, argv);
  const Communicator comm = Communicator::world();
  if (comm.is_root()) std::printf("operation,ranks,bytes,seconds\n");
  for (std::size_t bytes = 8; bytes <= (std::size_t{1} << 24); bytes *= 8) exchange_row(comm, bytes);
  for (std::size_t bytes = 8; bytes <= (std::size_t{1} << 24); bytes *= 8) all_reduce_row(comm, bytes);
  return 0;
}
