#pragma once
// Snapshots and checkpoints of particles spread over MPI ranks, written without gathering them
// anywhere: the particles are regrouped into ID ranges, and rank 0 writes the file one rank's range
// at a time (memory O(N/P) on every rank). The files are the ones a single process writes (snapshots
// byte for byte; checkpoints in ID order).
#include <string>

#include "core/particles.hpp"
#include "io/checkpoint.hpp"
#include "io/snapshot.hpp"
#include "parallel/communicator.hpp"

namespace sphdisk {

// Collective. A failure on rank 0 is rethrown there as UserError and as PeerError elsewhere.
template <int D>
void write_snapshot(const Communicator& comm, const std::string& path, const Particles<D>& p, const SnapshotMeta& meta);

void write_checkpoint(const Communicator& comm, const std::string& path, const Particles<2>& p, const RunState& s);

}  // namespace sphdisk
