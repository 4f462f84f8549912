#include "app/run_records.hpp"

#include <sstream>

namespace sphdisk {

namespace {

DomainTraffic difference(const DomainTraffic& a, const DomainTraffic& b) {
  return {a.migration - b.migration, a.halo_build - b.halo_build, a.halo_refresh - b.halo_refresh,
          a.reductions - b.reductions};
}

}  // namespace

std::string traffic_json(const Traffic& t) {
  std::ostringstream os;
  os << "{\"exchanges\": " << t.exchanges << ", \"messages\": " << t.messages << ", \"bytes\": " << t.bytes
     << ", \"reductions\": " << t.reductions << ", \"reduction_bytes\": " << t.reduction_bytes << '}';
  return os.str();
}

std::string traffic_json(const DomainTraffic& t) {
  return "{\"migration\": " + traffic_json(t.migration) + ", \"halo_build\": " + traffic_json(t.halo_build) +
         ", \"halo_refresh\": " + traffic_json(t.halo_refresh) + ", \"reductions\": " + traffic_json(t.reductions) +
         ", \"total\": " + traffic_json(t.total()) + '}';
}

std::string steps_json(const RunCounters& a, const RunCounters& b) {
  std::ostringstream os;
  os << "{\"steps\": " << b.step - a.step << ", \"rate_evaluations\": " << b.evaluations - a.evaluations
     << ", \"particle_updates\": " << b.updates - a.updates << ", \"pair_interactions\": " << b.pairs - a.pairs
     << ", \"smoothing_length_solves\": " << b.h_solves - a.h_solves
     << ", \"smoothing_length_sums\": " << b.h_sums - a.h_sums
     << ", \"traffic\": " << traffic_json(difference(b.traffic, a.traffic)) << '}';
  return os.str();
}

}  // namespace sphdisk
