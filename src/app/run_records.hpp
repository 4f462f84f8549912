#pragma once
// The work and traffic counters a run records per rank in ranks.json (docs/formats.md): a rank's
// counters at one moment, and the JSON of their difference over the steps of a run.
#include <cstddef>
#include <string>

#include "domain/distributed_domain.hpp"

namespace sphdisk {

// Work and traffic counters of this rank, at one moment (the steps' share is a difference).
struct RunCounters {
  long long step = 0;
  std::size_t evaluations = 0, updates = 0, pairs = 0, h_solves = 0, h_sums = 0;
  DomainTraffic traffic;
};

std::string traffic_json(const Traffic& t);
std::string traffic_json(const DomainTraffic& t);

// The counters of the steps between `begin` and `end` only: with begin at the first step of a run's
// advance and end after its last, no set-up (first distribution, start-up evaluation), no snapshot,
// no checkpoint after the last step (docs/performance.md, "Scaling model").
std::string steps_json(const RunCounters& begin, const RunCounters& end);

}  // namespace sphdisk
