#pragma once
// A run's output directory: the names of what a run writes there, the policy that keeps two runs'
// outputs from mixing (refuse, or with --overwrite remove the earlier run's files first), and the
// atomic text writes and the diagnostics table's trimming on resume.
#include <cstddef>
#include <string>

namespace sphdisk {

inline constexpr const char* kCheckpointName = "checkpoint.hdf5";
inline constexpr const char* kDiagnosticsName = "diagnostics.csv";
inline constexpr const char* kDiagnosticsHeader =
    "step,time,tau,dt,particles,mass,accreted_mass,kinetic_energy,internal_energy,angular_momentum,"
    "accreted_angular_momentum,wall_time";

// dir/snapshot_kkk.hdf5.
std::string snapshot_name(const std::string& dir, std::size_t k);

// Creates dir; refuses one holding an earlier run's results unless overwrite; checks it is writable.
void prepare_output_dir(const std::string& dir, bool overwrite);

// Whether a file of this name is one a run (or `sphdisk report`) writes into its directory.
bool written_by_a_run(const std::string& name);

// Removes every file of an earlier run from dir (--overwrite), before the new run writes anything.
void remove_earlier_run(const std::string& dir);

// Writes dir/name atomically (io/atomic_file.hpp).
void write_text_file(const std::string& dir, const std::string& name, const std::string& text);

// Keeps the rows of diagnostics.csv up to `step` (a resumed run continues after its checkpoint).
void truncate_diagnostics(const std::string& dir, long long step);

}  // namespace sphdisk
