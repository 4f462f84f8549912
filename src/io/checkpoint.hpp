#pragma once
// Checkpoints: everything needed to continue a run bit-for-bit, in one HDF5 file (portable across
// machines, thread and rank counts). Particles are stored in memory order (in ID order from a
// distributed run) with every field flagged kCheckpoint (and kRateState where RunState::rate_state
// asks for them: block timesteps; and kStepState where it was written inside a block cycle), but
// none its particles lacked (Particles::absent_fields); the run state (time, step, next output,
// accretion tallies, integrator state) and the resolved configuration are attributes. A 64-bit
// checksum over all of it detects corruption; it is a sum over rows (format 2), so ranks writing
// or reading their own rows can add theirs up.
// Written atomically (temporary file, fsync, rename): the previous checkpoint stays intact until
// the new one is complete.
#include <string>
#include <vector>

#include "core/particles.hpp"
#include "parallel/communicator.hpp"

namespace sphdisk {

struct RunState {
  double time = 0;
  long long step = 0;
  long long next_output = 0;        // index into output.tau of the next snapshot
  double accreted_mass = 0;
  double accreted_angular_momentum = 0;
  double smoothing_length = 0;
  std::vector<double> integrator;   // the integrator's own state (e.g. next RK step size)
  bool rate_state = false;          // the particles' kRateState fields are (to be) in the checkpoint too
  bool step_state = false;          // written inside a step (a block cycle): the kStepState fields are
                                    // in it too, and `integrator` is the step's state
                                    // (Integrator::step_state; time and step are those before it)
  std::string config_toml;          // resolved configuration of the run
  std::string run_id;               // the run's identity as it started (app/run_identity.hpp), kept
                                    // by its resumes whatever they override; "" before format 11
  double initial_mass = 0;          // a run from a file: its particles' and accreted mass at the start
                                    // (Header DiskMass); 0: problem.disc_mass's (and before format 11)
};

// The field flags whose fields a checkpoint holds: kCheckpoint, kRateState where the run needs those
// (RunState::rate_state), kStepState where it was written inside a step (RunState::step_state).
inline unsigned checkpoint_field_flags(const RunState& s) {
  return kCheckpoint | (s.rate_state ? kRateState : 0u) | (s.step_state ? kStepState : 0u);
}

template <int D>
void write_checkpoint(const std::string& path, const Particles<D>& p, const RunState& s);

// One checkpoint written by all ranks of comm together (collective): this rank's particles are rows
// [first_row, first_row + p.size()) of the file's n.
template <int D>
void write_checkpoint_share(const std::string& path, const Communicator& comm, std::size_t n, std::size_t first_row,
                            const Particles<D>& p, const RunState& s);

// Reads a checkpoint; on P ranks each rank reads share {rank, P} of the particles (1/P of the
// rows; collective: the checksum is checked over all shares). Throws UserError on every rank if
// the file is missing, truncated, corrupt (checksum) or not a checkpoint.
template <int D>
Particles<D> read_checkpoint(const std::string& path, RunState& s, const Communicator& comm = Communicator::self());

// The run's dimension (2 or 3) that a checkpoint records, so that it is read into particles of it.
int checkpoint_dimension(const std::string& path);

}  // namespace sphdisk
