#include "io/distributed_snapshot.hpp"

#include <numeric>

#include "core/error.hpp"
#include "domain/distributed_domain.hpp"

namespace sphdisk {

template <int D>
void write_snapshot(const Communicator& comm, const std::string& path, const Particles<D>& p, const SnapshotMeta& meta) {
  if (comm.size() == 1) {
    write_snapshot(path, p, meta);
    return;
  }
  const Particles<D> mine = regroup_by_id(comm, p);  // ID-ordered, and ranks' ranges ascend
  SnapshotMeta m = meta;
  m.box_size = comm.max(std::max(meta.box_size, snapshot_box_size(p)));
  const std::uint64_t n = comm.sum(p.size());
  int next = 0;  // rank whose range is written next (rank 0 counts the rounds)
  std::string error;
  if (comm.is_root()) {
    Particles<D> block;
    std::vector<std::size_t> order;
    try {
      write_snapshot_blocks<D>(path, n, m, [&](SnapshotBlock<D>& b) {
        if (next == comm.size()) return false;
        block = next == 0 ? mine : send_to_root(comm, next, mine);
        ++next;
        order.resize(block.size());
        std::iota(order.begin(), order.end(), std::size_t{0});
        b = SnapshotBlock<D>{&block, &order};
        return true;
      });
    } catch (const UserError& e) {
      error = e.what();
    }
    for (next = std::max(next, 1); next < comm.size(); ++next) send_to_root(comm, next, mine);  // rounds left
  } else {
    for (int r = 1; r < comm.size(); ++r) send_to_root(comm, r, mine);
  }
  if (comm.any(!error.empty())) {
    if (comm.is_root()) throw UserError(error);
    throw PeerError("rank 0 failed to write " + path);
  }
}

template void write_snapshot(const Communicator&, const std::string&, const Particles<2>&, const SnapshotMeta&);
template void write_snapshot(const Communicator&, const std::string&, const Particles<3>&, const SnapshotMeta&);

}  // namespace sphdisk
