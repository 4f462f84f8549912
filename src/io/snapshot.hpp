#pragma once
// HDF5 snapshots in the GADGET-4 / SWIFT layout of shared/design/formats.md, read by yt, SPLASH and
// h5py tools. Datasets come from the particle field table (fields flagged kSnapshot); particles
// are written in ID order, so the file does not depend on memory order, threads or ranks.
// Files are written atomically: to a temporary name, flushed to disk, then renamed.
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "core/particles.hpp"
#include "core/units.hpp"

namespace sphdisk {

struct SnapshotMeta {
  double time = 0;                 // code units
  double tau = 0;                  // viscous time 12 nu t / r0^2 (ring runs)
  double viscosity = 0;            // nu, code units
  double ring_radius = 1;          // r0, code units
  double disc_mass = 0;            // initial disc mass, code units
  double accreted_mass = 0;        // code units
  double accreted_angular_momentum = 0;
  long long step = 0;
  double box_size = 0;             // set by the writer from the particle extent
  bool energy = false;             // InternalEnergy written / present
  UnitSystem units{1, 1, 1};
  std::vector<std::pair<std::string, std::string>> parameters;  // resolved config (key, TOML text)
};

template <int D>
void write_snapshot(const std::string& path, const Particles<D>& p, const SnapshotMeta& meta);

// The same file written from consecutive blocks of particles in ascending ID order (a distributed
// run hands them over one rank at a time, so no process holds all particles). next_block fills the
// next block and returns true, or returns false when all n particles were given; meta.box_size is
// written as given (snapshot_box_size of all particles).
template <int D>
struct SnapshotBlock {
  const Particles<D>* particles = nullptr;
  const std::vector<std::size_t>* order = nullptr;  // the block's rows: particles[order[0]], ...
};
template <int D>
void write_snapshot_blocks(const std::string& path, std::size_t n, const SnapshotMeta& meta,
                           const std::function<bool(SnapshotBlock<D>&)>& next_block);
template <int D>
double snapshot_box_size(const Particles<D>& p);

// Reads a snapshot. With code_units given and a /Units group in the file, values are converted to
// those code units; with nullptr (or no /Units) they are kept as stored. Throws UserError naming
// what is wrong.
template <int D>
Particles<D> read_snapshot(const std::string& path, const UnitSystem* code_units, SnapshotMeta& meta);


}  // namespace sphdisk
