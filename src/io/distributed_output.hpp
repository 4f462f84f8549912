#pragma once
// Snapshots and checkpoints of particles spread over MPI ranks, written without gathering them
// anywhere: the particles are regrouped into ID ranges, and every rank writes its range into the
// one file collectively (MPI-IO; memory O(N/P) on every rank). The files are byte for byte the ones
// a single process writes (checkpoints then in ID order).
#include <string>

#include "core/particles.hpp"
#include "io/checkpoint.hpp"
#include "io/snapshot.hpp"
#include "parallel/communicator.hpp"

namespace sphdisk {

// Collective. A failure is a UserError on rank 0 and a PeerError elsewhere.
template <int D>
void write_snapshot(const Communicator& comm, const std::string& path, const Particles<D>& p, const SnapshotMeta& meta);

template <int D>
void write_checkpoint(const Communicator& comm, const std::string& path, const Particles<D>& p, const RunState& s);

}  // namespace sphdisk
