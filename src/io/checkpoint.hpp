#pragma once
// Checkpoints: everything needed to continue a run bit-for-bit, in one HDF5 file (portable across
// machines, thread and rank counts). Particles are stored in memory order (in ID order from a
// distributed run) with every field flagged
// kCheckpoint; the run state (time, step, next output, accretion tallies, integrator state) and the
// resolved configuration are attributes. A 64-bit checksum over all of it detects corruption.
// Written atomically (temporary file, fsync, rename): the previous checkpoint stays intact until
// the new one is complete.
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "core/particles.hpp"

namespace sphdisk {

struct RunState {
  double time = 0;
  long long step = 0;
  long long next_output = 0;        // index into output.tau of the next snapshot
  double accreted_mass = 0;
  double accreted_angular_momentum = 0;
  double smoothing_length = 0;
  std::vector<double> integrator;   // the integrator's own state (e.g. next RK step size)
  std::string config_toml;          // resolved configuration of the run
};

void write_checkpoint(const std::string& path, const Particles<2>& p, const RunState& s);

// The same file from `blocks` consecutive blocks of particles, field by field: block(field, b)
// returns block b with at least that field filled (a distributed run hands them over one rank at
// a time, io/distributed_output.hpp). n: the total number of particles.
using CheckpointBlock = std::function<const Particles<2>&(std::string_view field, std::size_t b)>;
void write_checkpoint_blocks(const std::string& path, std::size_t n, const RunState& s, std::size_t blocks,
                             const CheckpointBlock& block);

// Throws UserError if the file is missing, truncated, corrupt (checksum) or not a checkpoint.
Particles<2> read_checkpoint(const std::string& path, RunState& s);

}  // namespace sphdisk
