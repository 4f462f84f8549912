#include "parallel/communicator.hpp"

#include <cstdlib>
#include <cstring>
#include <stdexcept>

#ifdef SPHDISK_HAVE_MPI
#include <mpi.h>
#endif

namespace sphdisk {

namespace {
Traffic g_traffic;  // only the main thread communicates (MPI_THREAD_FUNNELED)
}  // namespace

Traffic& Traffic::operator+=(const Traffic& o) {
  exchanges += o.exchanges;
  messages += o.messages;
  bytes += o.bytes;
  reductions += o.reductions;
  reduction_bytes += o.reduction_bytes;
  return *this;
}

Traffic Traffic::operator-(const Traffic& o) const {
  return {exchanges - o.exchanges, messages - o.messages, bytes - o.bytes, reductions - o.reductions,
          reduction_bytes - o.reduction_bytes};
}

Traffic sent_traffic() { return g_traffic; }

#ifdef SPHDISK_HAVE_MPI

namespace {

MPI_Comm comm_of(void* h) { return *static_cast<MPI_Comm*>(h); }

void check(int rc, const char* what) {
  if (rc != MPI_SUCCESS) throw std::runtime_error(std::string("MPI call failed: ") + what);
}

}  // namespace

Communicator Communicator::world() {
  static MPI_Comm world = MPI_COMM_WORLD;
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (!initialised) return Communicator(0, 1, nullptr);  // e.g. unit tests: one process, no MPI
  int rank = 0, size = 1;
  check(MPI_Comm_rank(world, &rank), "MPI_Comm_rank");
  check(MPI_Comm_size(world, &size), "MPI_Comm_size");
  return Communicator(rank, size, &world);
}

// In-place all-reduce of n values; a communicator of one rank has nothing to combine.
void all_reduce(void* handle, int size, void* data, std::size_t n, MPI_Datatype type, MPI_Op op) {
  if (size == 1) return;
  ++g_traffic.reductions;
  g_traffic.reduction_bytes += n * 8;  // every type reduced here is 8 bytes wide
  check(MPI_Allreduce(MPI_IN_PLACE, data, static_cast<int>(n), type, op, comm_of(handle)), "MPI_Allreduce");
}

double Communicator::min(double x) const {
  all_reduce(handle_, size_, &x, 1, MPI_DOUBLE, MPI_MIN);
  return x;
}
double Communicator::max(double x) const {
  all_reduce(handle_, size_, &x, 1, MPI_DOUBLE, MPI_MAX);
  return x;
}
std::uint64_t Communicator::sum(std::uint64_t x) const {
  all_reduce(handle_, size_, &x, 1, MPI_UINT64_T, MPI_SUM);
  return x;
}
void Communicator::min(std::span<double> x) const { all_reduce(handle_, size_, x.data(), x.size(), MPI_DOUBLE, MPI_MIN); }
void Communicator::max(std::span<double> x) const { all_reduce(handle_, size_, x.data(), x.size(), MPI_DOUBLE, MPI_MAX); }
void Communicator::max(std::span<std::uint64_t> x) const {
  all_reduce(handle_, size_, x.data(), x.size(), MPI_UINT64_T, MPI_MAX);
}
void Communicator::sum(std::span<std::uint64_t> x) const {
  all_reduce(handle_, size_, x.data(), x.size(), MPI_UINT64_T, MPI_SUM);
}
std::vector<double> Communicator::gather_values(std::span<const double> mine) const {
  if (size_ == 1) return {mine.begin(), mine.end()};
  std::vector<double> all(mine.size() * static_cast<std::size_t>(size_));
  ++g_traffic.reductions;
  g_traffic.reduction_bytes += mine.size_bytes();
  const int n = static_cast<int>(mine.size());
  check(MPI_Allgather(mine.data(), n, MPI_DOUBLE, all.data(), n, MPI_DOUBLE, comm_of(handle_)), "MPI_Allgather");
  return all;
}


bool Communicator::any(bool x) const {
  if (size_ == 1) return x;
  int v = x ? 1 : 0;
  ++g_traffic.reductions;
  g_traffic.reduction_bytes += sizeof v;
  check(MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_INT, MPI_MAX, comm_of(handle_)), "MPI_Allreduce");
  return v != 0;
}

std::vector<std::vector<std::byte>> Communicator::exchange(const std::vector<std::vector<std::byte>>& send) const {
  const auto p = static_cast<std::size_t>(size_);
  if (send.size() != p) throw std::logic_error("Communicator::exchange: one buffer per rank expected");
  if (size_ == 1) return send;
  // Counts first, then the data; MPI counts are int, so large messages go as 8-byte words.
  std::vector<long long> send_bytes(p), recv_bytes(p);
  for (std::size_t r = 0; r < p; ++r) send_bytes[r] = static_cast<long long>(send[r].size());
  check(MPI_Alltoall(send_bytes.data(), 1, MPI_LONG_LONG, recv_bytes.data(), 1, MPI_LONG_LONG, comm_of(handle_)),
        "MPI_Alltoall");
  auto words = [](long long bytes) { return static_cast<int>((bytes + 7) / 8); };
  std::vector<int> scount(p), sdispl(p), rcount(p), rdispl(p);
  int stotal = 0, rtotal = 0;
  for (std::size_t r = 0; r < p; ++r) {
    scount[r] = words(send_bytes[r]);
    rcount[r] = words(recv_bytes[r]);
    sdispl[r] = stotal;
    rdispl[r] = rtotal;
    stotal += scount[r];
    rtotal += rcount[r];
  }
  ++g_traffic.exchanges;
  for (std::size_t r = 0; r < p; ++r)
    if (r != static_cast<std::size_t>(rank_) && !send[r].empty()) {
      ++g_traffic.messages;
      g_traffic.bytes += send[r].size();
    }
  std::vector<std::uint64_t> sbuf(static_cast<std::size_t>(stotal)), rbuf(static_cast<std::size_t>(rtotal));
  for (std::size_t r = 0; r < p; ++r)
    if (!send[r].empty()) std::memcpy(sbuf.data() + sdispl[r], send[r].data(), send[r].size());
  check(MPI_Alltoallv(sbuf.data(), scount.data(), sdispl.data(), MPI_UINT64_T, rbuf.data(), rcount.data(),
                      rdispl.data(), MPI_UINT64_T, comm_of(handle_)),
        "MPI_Alltoallv");
  std::vector<std::vector<std::byte>> recv(p);
  for (std::size_t r = 0; r < p; ++r) {
    recv[r].resize(static_cast<std::size_t>(recv_bytes[r]));
    if (!recv[r].empty()) std::memcpy(recv[r].data(), rbuf.data() + rdispl[r], recv[r].size());
  }
  return recv;
}

std::vector<std::uint64_t> Communicator::all_to_all(const std::vector<std::uint64_t>& send) const {
  const auto p = static_cast<std::size_t>(size_);
  if (send.size() != p) throw std::logic_error("Communicator::all_to_all: one value per rank expected");
  if (size_ == 1) return send;
  std::vector<std::uint64_t> recv(p);
  ++g_traffic.exchanges;  // like the byte counts that open every exchange: no messages of its own
  check(MPI_Alltoall(send.data(), 1, MPI_UINT64_T, recv.data(), 1, MPI_UINT64_T, comm_of(handle_)), "MPI_Alltoall");
  return recv;
}

void Communicator::barrier() const {
  if (size_ > 1) ++g_traffic.reductions;
  if (size_ > 1) check(MPI_Barrier(comm_of(handle_)), "MPI_Barrier");
}

namespace {
// Started by an MPI launcher (mpirun/mpiexec of OpenMPI or MPICH, srun with PMI or PMIx)?
bool launched_by_mpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE", "PMI_RANK", "MPI_LOCALNRANKS"})
    if (std::getenv(v)) return true;
  return false;
}
}  // namespace

constexpr int kPointToPointTag = 7;

void Communicator::send(int to, const std::vector<std::byte>& bytes) const {
  ++g_traffic.messages;
  g_traffic.bytes += bytes.size();
  check(MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, to, kPointToPointTag, comm_of(handle_)),
        "MPI_Send");
}

// The next message from `source` (MPI_ANY_SOURCE: from any rank); its sender goes to `from`.
std::vector<std::byte> receive(void* handle, int source, int& from) {
  MPI_Status status;
  check(MPI_Probe(source, kPointToPointTag, comm_of(handle), &status), "MPI_Probe");
  int count = 0;
  MPI_Get_count(&status, MPI_BYTE, &count);
  std::vector<std::byte> bytes(static_cast<std::size_t>(count));
  from = status.MPI_SOURCE;
  check(MPI_Recv(bytes.data(), count, MPI_BYTE, from, kPointToPointTag, comm_of(handle), MPI_STATUS_IGNORE), "MPI_Recv");
  return bytes;
}

std::vector<std::byte> Communicator::receive_from_any(int& from) const { return receive(handle_, MPI_ANY_SOURCE, from); }

std::vector<std::byte> Communicator::receive_from(int from) const {
  int sender = from;
  return receive(handle_, from, sender);
}

MpiSession::MpiSession(int& argc, char**& argv) {
  if (!launched_by_mpi()) return;  // one process: no MPI (singleton start-up costs time and shared memory)
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
}

MpiSession::~MpiSession() {
  int initialised = 0, finalised = 0;
  MPI_Initialized(&initialised);
  MPI_Finalized(&finalised);
  if (initialised && !finalised) MPI_Finalize();
}

void abort_all_ranks(int code) {
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (initialised) MPI_Abort(MPI_COMM_WORLD, code);
  std::_Exit(code);
}

#else  // one rank

Communicator Communicator::world() { return Communicator(0, 1, nullptr); }
double Communicator::min(double x) const { return x; }
double Communicator::max(double x) const { return x; }
std::uint64_t Communicator::sum(std::uint64_t x) const { return x; }
void Communicator::min(std::span<double>) const {}
void Communicator::max(std::span<double>) const {}
void Communicator::max(std::span<std::uint64_t>) const {}
void Communicator::sum(std::span<std::uint64_t>) const {}
bool Communicator::any(bool x) const { return x; }
std::vector<double> Communicator::gather_values(std::span<const double> mine) const { return {mine.begin(), mine.end()}; }

std::vector<std::vector<std::byte>> Communicator::exchange(const std::vector<std::vector<std::byte>>& send) const {
  return send;
}
std::vector<std::uint64_t> Communicator::all_to_all(const std::vector<std::uint64_t>& send) const { return send; }
void Communicator::barrier() const {}
void Communicator::send(int, const std::vector<std::byte>&) const {
  throw std::logic_error("Communicator::send: there is no other rank");
}
std::vector<std::byte> Communicator::receive_from(int) const {
  throw std::logic_error("Communicator::receive_from: there is no other rank");
}
std::vector<std::byte> Communicator::receive_from_any(int&) const {
  throw std::logic_error("Communicator::receive_from_any: there is no other rank");
}
MpiSession::MpiSession(int&, char**&) {}
MpiSession::~MpiSession() = default;
void abort_all_ranks(int code) { std::_Exit(code); }

#endif

double Communicator::sum_in_rank_order(double x) const {
  double s = 0;
  for (const double v : gather_values(std::span<const double>(&x, 1))) s += v;
  return s;
}

std::vector<std::vector<std::byte>> Communicator::all_gather(const std::vector<std::byte>& mine) const {
  return exchange(std::vector<std::vector<std::byte>>(static_cast<std::size_t>(size_), mine));
}

std::vector<std::string> Communicator::gather_to_root(const std::string& mine) const {
  if (size_ == 1) return {mine};
  std::vector<std::vector<std::byte>> send(static_cast<std::size_t>(size_));
  send[0].assign(reinterpret_cast<const std::byte*>(mine.data()), reinterpret_cast<const std::byte*>(mine.data()) + mine.size());
  std::vector<std::string> out;
  for (const auto& b : exchange(send))
    if (rank_ == 0) out.emplace_back(reinterpret_cast<const char*>(b.data()), b.size());
  return out;
}

}  // namespace sphdisk
