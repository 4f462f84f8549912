#include "io/distributed_output.hpp"

#include <numeric>

#include "domain/distributed_domain.hpp"

namespace sphdisk {

namespace {
// The first file row of this rank's particles: the ranks' ID ranges ascend with rank.
std::size_t first_row(const Communicator& comm, std::size_t mine) {
  std::vector<std::uint64_t> counts(static_cast<std::size_t>(comm.size()), 0);
  counts[static_cast<std::size_t>(comm.rank())] = mine;
  comm.sum(counts);
  return std::accumulate(counts.begin(), counts.begin() + comm.rank(), std::size_t{0});
}

// The names of the fields carrying any of `flags` (only these are regrouped for a file).
template <int D>
FieldNames fields_with(unsigned flags) {
  FieldNames names;
  Particles<D>{}.for_each_field([&](const FieldInfo& info, const auto&) {
    if (info.flags & flags) names.push_back(info.name);
  });
  return names;
}
}  // namespace

template <int D>
void write_snapshot(const Communicator& comm, const std::string& path, const Particles<D>& p, const SnapshotMeta& meta) {
  if (comm.size() == 1) {
    write_snapshot(path, p, meta);
    return;
  }
  const Particles<D> mine = regroup_by_id(comm, p, fields_with<D>(kSnapshot));  // ID-ordered; ranges ascend with rank
  SnapshotMeta m = meta;
  m.box_size = comm.max(std::max(meta.box_size, snapshot_box_size(p)));
  std::vector<std::size_t> order(mine.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  write_snapshot_share(path, comm, comm.sum(p.size()), first_row(comm, mine.size()), mine, order, m);
}

template <int D>
void write_checkpoint(const Communicator& comm, const std::string& path, const Particles<D>& p, const RunState& s) {
  if (comm.size() == 1) {
    write_checkpoint(path, p, s);
    return;
  }
  const Particles<D> mine = regroup_by_id(comm, p, fields_with<D>(checkpoint_field_flags(s)));
  write_checkpoint_share(path, comm, comm.sum(p.size()), first_row(comm, mine.size()), mine, s);
}

template void write_snapshot(const Communicator&, const std::string&, const Particles<2>&, const SnapshotMeta&);
template void write_snapshot(const Communicator&, const std::string&, const Particles<3>&, const SnapshotMeta&);
template void write_checkpoint(const Communicator&, const std::string&, const Particles<2>&, const RunState&);
template void write_checkpoint(const Communicator&, const std::string&, const Particles<3>&, const RunState&);

}  // namespace sphdisk
