#include "io/distributed_output.hpp"

#include <numeric>
#include <stdexcept>

#include "core/error.hpp"
#include "domain/distributed_domain.hpp"

namespace sphdisk {

namespace {

template <int D>
using FetchBlock = std::function<const Particles<D>&(std::size_t round, int from)>;

// Rank 0 runs write(fetch): fetch(round, from) returns rank `from`'s ID-ordered particles with the
// fields of rounds[round] (from = 0: its own, all fields). The other ranks send their blocks round
// by round, ranks 1..P-1 in turn, so write must fetch in that order. If the write fails part-way,
// rank 0 still takes part in the rounds left; the failure is then reported on every rank.
template <int D>
void write_on_root(const Communicator& comm, const Particles<D>& mine, const std::vector<FieldNames>& rounds,
                   const std::function<void(const FetchBlock<D>&)>& write) {
  const auto senders = static_cast<std::size_t>(comm.size() - 1);
  const std::size_t total = rounds.size() * senders;
  if (!comm.is_root())
    for (const FieldNames& fields : rounds)
      for (int from = 1; from < comm.size(); ++from) send_to_root(comm, from, mine, fields);
  run_on_root(comm, [&] {
    std::size_t done = 0;
    Particles<D> block;
    const FetchBlock<D> fetch = [&](std::size_t round, int from) -> const Particles<D>& {
      if (from == 0) return mine;
      if (round * senders + static_cast<std::size_t>(from - 1) != done)
        throw std::logic_error("write_on_root: blocks fetched out of order");
      block = send_to_root(comm, from, mine, rounds[round]);
      ++done;
      return block;
    };
    auto finish_rounds = [&] {
      for (; done < total; ++done) send_to_root(comm, static_cast<int>(1 + done % senders), mine, rounds[done / senders]);
    };
    try {
      write(fetch);
    } catch (const UserError&) {
      finish_rounds();  // the other ranks are still sending
      throw;
    }
    finish_rounds();
  });
}

}  // namespace

template <int D>
void write_snapshot(const Communicator& comm, const std::string& path, const Particles<D>& p, const SnapshotMeta& meta) {
  if (comm.size() == 1) {
    write_snapshot(path, p, meta);
    return;
  }
  const Particles<D> mine = regroup_by_id(comm, p);  // ID-ordered, and the ranks' ranges ascend
  SnapshotMeta m = meta;
  m.box_size = comm.max(std::max(meta.box_size, snapshot_box_size(p)));
  const std::uint64_t n = comm.sum(p.size());
  write_on_root<D>(comm, mine, {FieldNames{}}, [&](const FetchBlock<D>& fetch) {
    int from = 0;
    std::vector<std::size_t> order;
    write_snapshot_blocks<D>(path, n, m, [&](SnapshotBlock<D>& b) {
      if (from == comm.size()) return false;
      const Particles<D>& block = fetch(0, from++);
      order.resize(block.size());
      std::iota(order.begin(), order.end(), std::size_t{0});
      b = SnapshotBlock<D>{&block, &order};
      return true;
    });
  });
}

void write_checkpoint(const Communicator& comm, const std::string& path, const Particles<2>& p, const RunState& s) {
  if (comm.size() == 1) {
    write_checkpoint(path, p, s);
    return;
  }
  const Particles<2> mine = regroup_by_id(comm, p);
  const std::uint64_t n = comm.sum(p.size());
  std::vector<FieldNames> rounds;  // one field per round, in the writer's (table) order
  mine.for_each_field([&](const FieldInfo& info, const auto&) {
    if (info.flags & kCheckpoint) rounds.push_back(FieldNames{info.name});
  });
  write_on_root<2>(comm, mine, rounds, [&](const FetchBlock<2>& fetch) {
    write_checkpoint_blocks(path, n, s, static_cast<std::size_t>(comm.size()),
                            [&](std::string_view field, std::size_t b) -> const Particles<2>& {
                              std::size_t round = 0;
                              while (rounds[round][0] != field) ++round;
                              return fetch(round, static_cast<int>(b));
                            });
  });
}

template void write_snapshot(const Communicator&, const std::string&, const Particles<2>&, const SnapshotMeta&);
template void write_snapshot(const Communicator&, const std::string&, const Particles<3>&, const SnapshotMeta&);

}  // namespace sphdisk
