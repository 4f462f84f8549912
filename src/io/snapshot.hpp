#pragma once
// HDF5 snapshots in the GADGET-4 / SWIFT layout of docs/formats.md ("Snapshot files"), read by yt
// (as SWIFT files) and h5py tools. Datasets come from the particle field table (fields flagged
// kSnapshot); particles are written in ID order, so the file does not depend on memory order, threads
// or ranks. Files are written atomically: to a temporary name, flushed to disk, then renamed.
// Coordinates in a file lie in [0, BoxSize]^3 with the central mass at Header/PointMassPosition (the
// box centre); in memory positions are relative to the central mass, and the reader subtracts it.
#include <string>
#include <utility>
#include <vector>

#include "core/particles.hpp"
#include "core/units.hpp"
#include "io/hdf5_util.hpp"
#include "parallel/communicator.hpp"

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
  double box_size = 0;             // set by the writer: snapshot_box_size
  bool energy = false;             // InternalEnergy written / present
  int dimension = 2;               // the run's (Header SimulationDimension; read back, 2 where absent)
  UnitSystem units{1, 1, 1};
  std::vector<std::pair<std::string, std::string>> parameters;  // resolved config (key, TOML text)
  // A parameter's TOML text by key; "" where absent.
  std::string parameter(const std::string& key) const {
    for (const auto& [k, text] : parameters)
      if (k == key) return text;
    return "";
  }
  std::string run_id;              // Header RunID (app/run_identity.hpp); "" where absent
  std::string problem;             // Header Problem: "ring" (the generated ring) or "initial_conditions" (from a file); "" where absent
};

template <int D>
void write_snapshot(const std::string& path, const Particles<D>& p, const SnapshotMeta& meta);

// One snapshot written by all ranks of comm together (collective). This rank's rows are
// [first_row, first_row + order.size()) of the file's n: particles[order[0]], particles[order[1]], ...;
// the ranks' rows tile [0, n) in ascending ID order. meta.box_size is written as given
// (snapshot_box_size of all particles).
template <int D>
void write_snapshot_share(const std::string& path, const Communicator& comm, std::size_t n, std::size_t first_row,
                          const Particles<D>& particles, const std::vector<std::size_t>& order, const SnapshotMeta& meta);
// The box edge written: twice the particles' largest |x_c| + 2 h (every kernel inside), rounded up
// to 4 significant bits.
template <int D>
double snapshot_box_size(const Particles<D>& p);

// Reads a snapshot's particles, or one share of them (each of P ranks reads 1/P of the rows). With
// code_units given and a /Units group in the file, values are converted to those code units; with
// nullptr (or no /Units) they are kept as stored. Throws UserError naming what is wrong. IDs are
// checked to be unique within what was read (across shares: ids_unique in the domain).
// The run's dimension a snapshot records (Header SimulationDimension; `unrecorded` where absent, as
// in other codes' files), so that it is read into particles of it.
int snapshot_dimension(const std::string& path, int unrecorded = 2);
// The run identity a snapshot records (Header RunID; "" where absent).
std::string snapshot_run_id(const std::string& path);

template <int D>
Particles<D> read_snapshot(const std::string& path, const UnitSystem* code_units, SnapshotMeta& meta,
                           h5::RowShare share = {});


}  // namespace sphdisk
