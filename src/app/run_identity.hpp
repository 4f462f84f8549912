#pragma once
// A run's identity: a hash of the settings that decide its results (problem.*, physics.*, sph.*,
// integrator.*), written into every snapshot's Header as RunID so that tools can refuse to mix the
// outputs of different runs in one directory (tools/report.py). Output times, checkpoint cadence,
// threads, ranks and the output directory do not enter it: runs that differ only in those give the
// same particles at the same times, and a resumed run keeps its identity.
#include <string>

#include "core/config.hpp"

namespace sphdisk {

std::string run_identity(const Config& cfg);  // 16 hex digits

}  // namespace sphdisk
