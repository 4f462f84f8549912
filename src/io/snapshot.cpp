#include <cstdio>
#include "io/snapshot.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/build_info.hpp"
#include "core/error.hpp"
#include "core/toml.hpp"
#include "io/atomic_file.hpp"
#include "io/hdf5_util.hpp"

namespace sphdisk {

namespace {

void write_parameters(hid_t file, const SnapshotMeta& meta) {
  h5::Handle g = h5::create_group(file, "Parameters");
  for (const auto& [key, text] : meta.parameters) {
    toml::table t;
    try {
      t = toml::parse("v = " + text);
    } catch (const toml::parse_error&) {
      h5::write_attr(g, key, text);
      continue;
    }
    const toml::node& v = *t.get("v");
    if (v.is_integer()) h5::write_attr(g, key, static_cast<long long>(*v.value<long long>()));
    else if (v.is_floating_point()) h5::write_attr(g, key, *v.value<double>());
    else if (v.is_boolean()) h5::write_attr(g, key, static_cast<long long>(*v.value<bool>()));
    else if (v.is_string()) h5::write_attr(g, key, *v.value<std::string>());
    else if (const toml::array* empty = v.as_array(); empty && empty->empty()) h5::write_attr(g, key, text);  // HDF5 has no empty attribute
    else if (const toml::array* a = v.as_array()) {
      std::vector<double> xs;
      for (const auto& e : *a) xs.push_back(e.value<double>().value_or(0.0));
      h5::write_attr(g, key, xs);
    }
  }
}

// The written box: the particles' extent (snapshot_box_size), or 1 without particles, as readers
// divide by it.
double written_box_size(const SnapshotMeta& meta) { return meta.box_size > 0 ? meta.box_size : 1.0; }

// Where the central mass sits in the file: the box centre, so that Coordinates lie in [0, BoxSize]^3,
// the domain SWIFT readers (yt) assume. Positions in memory stay centred on the origin.
double point_mass_offset(const SnapshotMeta& meta) { return written_box_size(meta) / 2; }

void write_header(hid_t file, std::size_t n, int dim, const SnapshotMeta& meta) {
  h5::Handle g = h5::create_group(file, "Header");
  std::vector<std::uint64_t> npart(6, 0);
  npart[0] = n;
  std::vector<std::uint32_t> low(6, 0), high(6, 0);
  low[0] = static_cast<std::uint32_t>(n & 0xffffffffu);
  high[0] = static_cast<std::uint32_t>(n >> 32);
  h5::write_attr(g, "NumPart_ThisFile", npart);
  h5::write_attr(g, "NumPart_Total", low);
  h5::write_attr(g, "NumPart_Total_HighWord", high);
  h5::write_attr(g, "MassTable", std::vector<double>(6, 0.0));
  h5::write_attr(g, "Time", meta.time);
  h5::write_attr(g, "Redshift", 0.0);
  // Open boundaries: the box only has to hold every particle and its kernel (SWIFT's three edges).
  h5::write_attr(g, "BoxSize", std::vector<double>(3, written_box_size(meta)));
  h5::write_attr(g, "PointMassPosition", std::vector<double>(3, point_mass_offset(meta)));
  h5::write_attr(g, "NumFilesPerSnapshot", 1LL);
  // Non-cosmological run: GADGET readers expect these keys.
  h5::write_attr(g, "Omega0", 0.0);
  h5::write_attr(g, "OmegaLambda", 0.0);
  h5::write_attr(g, "HubbleParam", 1.0);
  h5::write_attr(g, "Flag_DoublePrecision", 1LL);  // the datasets: doubles in every build
  // 1: a build with SPHDISK_SINGLE_PRECISION_FIELDS, whose Density values are floats (widened).
  h5::write_attr(g, "SinglePrecisionFields", kSinglePrecisionFields ? 1LL : 0LL);
  // Dimension is that of the Coordinates (yt 4.1 cannot index a SWIFT file with Dimension 2); the
  // run's own is SimulationDimension.
  h5::write_attr(g, "Dimension", 3LL);
  h5::write_attr(g, "SimulationDimension", static_cast<long long>(dim));
  // Code selects the reader (yt's SWIFT frontend); CodeName says which code wrote the file.
  h5::write_attr(g, "Code", std::string("SWIFT"));
  h5::write_attr(g, "CodeName", std::string("sphdisk"));
  h5::write_attr(g, "CodeVersion", std::string(code_version()));
  h5::write_attr(g, "BuildOptions", build_options());
  h5::write_attr(g, "ViscousTime", meta.tau);
  h5::write_attr(g, "KinematicViscosity", meta.viscosity);
  h5::write_attr(g, "RingRadius", meta.ring_radius);
  h5::write_attr(g, "DiskMass", meta.disc_mass);
  h5::write_attr(g, "AccretedMass", meta.accreted_mass);
  h5::write_attr(g, "AccretedAngularMomentum", meta.accreted_angular_momentum);
  h5::write_attr(g, "Step", meta.step);
  if (!meta.problem.empty()) h5::write_attr(g, "Problem", meta.problem);
  if (!meta.run_id.empty()) h5::write_attr(g, "RunID", meta.run_id);
}

// The cgs value of each code unit, under GADGET's names and SWIFT's (the names yt's SWIFT frontend
// reads; no temperature or current units: 1).
void write_units(hid_t file, const UnitSystem& u) {
  h5::Handle g = h5::create_group(file, "Units");
  h5::write_attr(g, "UnitLength_in_cm", u.length_cm);
  h5::write_attr(g, "UnitMass_in_g", u.mass_g);
  h5::write_attr(g, "UnitTime_in_s", u.time_s);
  h5::write_attr(g, "UnitVelocity_in_cm_per_s", u.velocity_cm_per_s());
  h5::write_attr(g, "Unit length in cgs (U_L)", u.length_cm);
  h5::write_attr(g, "Unit mass in cgs (U_M)", u.mass_g);
  h5::write_attr(g, "Unit time in cgs (U_t)", u.time_s);
  h5::write_attr(g, "Unit temperature in cgs (U_T)", 1.0);
  h5::write_attr(g, "Unit current in cgs (U_I)", 1.0);
}

// The groups a SWIFT reader opens besides Header, Units and Parameters: open boundaries, no
// cosmology; the scheme groups stay empty.
void write_swift_groups(hid_t file) {
  h5::write_attr(h5::create_group(file, "RuntimePars"), "PeriodicBoundariesOn", 0LL);
  h5::write_attr(h5::create_group(file, "Policy"), "cosmological integration", 0LL);
  h5::create_group(file, "HydroScheme");
  h5::create_group(file, "SubgridScheme");
}

// w rounded up to 4 significant bits (exactly), so that BoxSize and PointMassPosition read as short
// numbers and stay put while the particles' extent changes a little.
double round_up_short(double w) {
  if (!(w > 0) || !std::isfinite(w)) return w;
  const double step = std::ldexp(1.0, std::ilogb(w) - 3);
  return std::ceil(w / step) * step;
}

// One snapshot dataset per field flagged kSnapshot (InternalEnergy only with energy).
bool in_snapshot(const FieldInfo& info, const SnapshotMeta& meta) {
  return (info.flags & kSnapshot) && !((info.flags & kEnergyOnly) && !meta.energy);
}

template <class T, int D>
constexpr std::size_t snapshot_columns() {
  if constexpr (std::is_same_v<T, Vec<D>>) return 3;  // always N x 3 (z = 0 in 2D), as GADGET readers expect
  else if constexpr (is_mat_v<T>) return D * D;
  else return 1;
}

// Rows order[0..n) of one field, flattened to doubles (or IDs): snapshots hold doubles whatever the
// storage precision (Header Flag_DoublePrecision). Vectors get `shift` added to each of their 3 columns.
template <int D, class T>
void write_field_rows(hid_t ds, const std::vector<T>& field, const std::vector<std::size_t>& order, std::size_t first_row,
                      double shift, hid_t transfer) {
  const std::size_t n = order.size();
  if constexpr (std::is_same_v<T, std::uint64_t>) {
    std::vector<std::uint64_t> out(n);
    for (std::size_t k = 0; k < n; ++k) out[k] = field[order[k]];
    h5::write_rows(ds, out.data(), first_row, n, transfer);
  } else {
    constexpr std::size_t cols = snapshot_columns<T, D>();
    std::vector<double> flat(n * cols, 0.0);
    for (std::size_t k = 0; k < n; ++k) {
      const T& v = field[order[k]];
      if constexpr (std::is_floating_point_v<T>) flat[k] = v;  // float fields (kReduced) widened exactly
      else if constexpr (std::is_same_v<T, Vec<D>>) {
        for (int c = 0; c < D; ++c) flat[3 * k + static_cast<std::size_t>(c)] = v[c];
        if (shift != 0)
          for (std::size_t c = 0; c < 3; ++c) flat[3 * k + c] += shift;
      } else std::copy(v.c.begin(), v.c.end(), flat.begin() + static_cast<std::ptrdiff_t>(k * cols));
    }
    h5::write_rows(ds, flat.data(), first_row, n, cols, transfer);
  }
}

}  // namespace

template <int D>
double snapshot_box_size(const Particles<D>& p) {
  // The largest |x_c| + 2 h (the kernel's reach) over particles and axes; non-finite values (a debug
  // dump's) are left out, so that the other particles keep finite Coordinates.
  double half = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int c = 0; c < D; ++c) {
      const double reach = std::abs(p.pos[i][c]) + 2.0 * static_cast<double>(p.h[i]);
      if (std::isfinite(reach)) half = std::max(half, reach);
    }
  return 2.0 * round_up_short(half);
}

template <int D>
void write_snapshot_share(const std::string& path, const Communicator& comm, std::size_t n, std::size_t first_row,
                          const Particles<D>& particles, const std::vector<std::size_t>& order, const SnapshotMeta& meta) {
  write_hdf5_atomically(path, comm, [&](hid_t file, hid_t transfer) {
    write_header(file, n, D, meta);
    write_units(file, meta.units);
    write_parameters(file, meta);
    write_swift_groups(file);
    h5::Handle g = h5::create_group(file, "PartType0");
    particles.for_each_field([&](const FieldInfo& info, const auto& field) {
      using T = typename std::decay_t<decltype(field)>::value_type;
      if (!in_snapshot(info, meta)) return;
      const h5::Handle ds = h5::create_dataset(g, std::string(info.dataset), std::is_same_v<T, std::uint64_t>, n,
                                               snapshot_columns<T, D>());
      const double shift = info.dataset == "Coordinates" ? point_mass_offset(meta) : 0.0;
      write_field_rows<D>(ds, field, order, first_row, shift, transfer);
    });
  });
}

template <int D>
void write_snapshot(const std::string& path, const Particles<D>& p, const SnapshotMeta& meta) {
  std::vector<std::size_t> order(p.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return p.id[a] < p.id[b]; });
  SnapshotMeta m = meta;
  m.box_size = std::max(m.box_size, snapshot_box_size(p));
  write_snapshot_share(path, Communicator::self(), p.size(), 0, p, order, m);
}

namespace {
// The /Parameters and /Units that analysis reads back (the kernel, the point mass, where the initial
// conditions came from, a blast wave's gamma and energy, the units), as the TOML text the run resolved them to.
void read_analysis_parameters(hid_t file, const std::string& path, SnapshotMeta& meta) {
  if (h5::exists(file, "Parameters")) {
    h5::Handle g = h5::open_group(file, "Parameters", path);
    for (const char* key : {"sph.kernel", "problem.initial_conditions"})
      if (h5::has_attr(g, key)) {
        std::string quoted(1, '"');  // (appended, not "\"" + value: GCC 12 warns of that falsely, -Wrestrict)
        quoted += h5::read_attr_string(g, key, path);
        meta.parameters.emplace_back(key, quoted + '"');
      }
    for (const char* key : {"physics.central_mass", "physics.gamma", "problem.blast_energy"})
      if (h5::has_attr(g, key)) {
        char text[64];
        std::snprintf(text, sizeof text, "%.17g", h5::read_attr_double(g, key, path));
        meta.parameters.emplace_back(key, text);
      }
  }
  if (h5::exists(file, "Units")) {
    h5::Handle u = h5::open_group(file, "Units", path);
    meta.units = UnitSystem{h5::read_attr_double(u, "UnitLength_in_cm", path), h5::read_attr_double(u, "UnitMass_in_g", path),
                            h5::read_attr_double(u, "UnitTime_in_s", path)};
  }
}

// Header PointMassPosition, which readers subtract from Coordinates (3 values, file units); files
// without it hold positions relative to the central mass already.
std::vector<double> point_mass_position(hid_t header, const std::string& path) {
  if (!h5::has_attr(header, "PointMassPosition")) return std::vector<double>(3, 0.0);
  std::vector<double> centre = h5::read_attr_doubles(header, "PointMassPosition", path);
  if (centre.size() != 3 || !std::all_of(centre.begin(), centre.end(), [](double v) { return std::isfinite(v); }))
    throw UserError("'" + path + "': Header/PointMassPosition must hold 3 finite values");
  return centre;
}

template <int D>
Particles<D> read_snapshot_unisolated(const std::string& path, const UnitSystem* code_units, SnapshotMeta& meta,
                                      h5::RowShare share) {
  h5::Handle file = h5::open_file_readonly(path);
  h5::Handle header = h5::open_group(file, "Header", path);
  meta.time = h5::read_attr_double(header, "Time", path);
  auto optional = [&](const char* name, double fallback) {
    return h5::has_attr(header, name) ? h5::read_attr_double(header, name, path) : fallback;
  };
  meta.tau = optional("ViscousTime", -1);
  meta.accreted_mass = optional("AccretedMass", 0);
  meta.accreted_angular_momentum = optional("AccretedAngularMomentum", 0);
  const double step = optional("Step", 0);
  meta.step = step >= 0 && step <= 9.0e15 ? static_cast<long long>(step) : 0;

  // Scale factors from file units to code units; without /Units the file is taken as code units.
  double fl = 1, fm = 1, ft = 1;
  if (code_units && h5::exists(file, "Units")) {
    h5::Handle u = h5::open_group(file, "Units", path);
    fl = h5::read_attr_double(u, "UnitLength_in_cm", path) / code_units->length_cm;
    fm = h5::read_attr_double(u, "UnitMass_in_g", path) / code_units->mass_g;
    ft = h5::read_attr_double(u, "UnitTime_in_s", path) / code_units->time_s;
    if (!(fl > 0 && fm > 0 && ft > 0 && std::isfinite(fl * fm * ft)))
      throw UserError("'" + path + "': /Units holds non-positive or non-finite values");
  }
  meta.time *= ft;
  meta.viscosity = optional("KinematicViscosity", 0) * fl * fl / ft;
  meta.ring_radius = optional("RingRadius", 1) * fl;
  meta.disc_mass = optional("DiskMass", 0) * fm;
  meta.accreted_mass *= fm;
  meta.accreted_angular_momentum *= fm * fl * fl / ft;
  meta.dimension = static_cast<int>(optional("SimulationDimension", 2));
  meta.problem = h5::has_attr(header, "Problem") ? h5::read_attr_string(header, "Problem", path) : "";
  meta.run_id = h5::has_attr(header, "RunID") ? h5::read_attr_string(header, "RunID", path) : "";
  read_analysis_parameters(file, path, meta);
  if (code_units && h5::exists(file, "Units")) meta.units = *code_units;  // the values were converted to them

  const std::vector<double> centre = point_mass_position(header, path);

  h5::Handle g = h5::open_group(file, "PartType0", path);
  Particles<D> p;
  std::size_t n_file = 0;
  const std::vector<std::uint64_t> ids = h5::read_dataset_u64(g, "ParticleIDs", path, n_file, share);
  const std::size_t n = ids.size();
  p.resize(n);
  p.id = ids;
  meta.energy = h5::exists(g, "InternalEnergy");
  p.for_each_field([&](const FieldInfo& info, auto& field) {
    using T = typename std::decay_t<decltype(field)>::value_type;
    if constexpr (!std::is_same_v<T, std::uint64_t>) {
      if (!(info.flags & kSnapshot)) return;
      const std::string name(info.dataset);
      const bool required = name == "Coordinates" || name == "Velocities" || name == "Masses";
      if (!h5::exists(g, name)) {
        if (required) throw UserError("'" + path + "' has no dataset PartType0/" + name + ", which initial conditions need");
        return;
      }
      std::size_t rows, cols;
      const std::vector<double> raw = h5::read_dataset_doubles(g, name, path, rows, cols, share);
      if (rows != n_file)
        throw UserError("'" + path + "': PartType0/" + name + " has " + std::to_string(rows) + " rows but ParticleIDs has " + std::to_string(n_file));
      const double scale = std::pow(fl, info.length_exp) * std::pow(fm, info.mass_exp) * std::pow(ft, info.time_exp);
      for (double v : raw)
        if (!std::isfinite(v)) throw UserError("'" + path + "': PartType0/" + name + " contains NaN or Inf");
      if constexpr (std::is_floating_point_v<T>) {
        if (cols != 1) throw UserError("'" + path + "': PartType0/" + name + " must be 1-D");
        for (std::size_t k = 0; k < n; ++k) store(field[k], raw[k] * scale);
      } else if constexpr (std::is_same_v<T, Vec<D>>) {
        if (cols != 3 && cols != static_cast<std::size_t>(D))
          throw UserError("'" + path + "': PartType0/" + name + " must have 3 or " + std::to_string(D) + " columns");
        const bool positions = name == "Coordinates";
        for (std::size_t k = 0; k < n; ++k) {
          auto value = [&](std::size_t c) { return raw[k * cols + c] - (positions ? centre[c] : 0.0); };
          for (int c = 0; c < D; ++c) field[k][c] = value(static_cast<std::size_t>(c)) * scale;
          for (std::size_t c = D; c < cols; ++c)
            if (value(c) != 0.0)
              throw UserError("'" + path + "': PartType0/" + name + " has non-zero z components but the run is " + std::to_string(D) + "D (sph.dimension = 3 runs it in 3D)");
        }
      }
    }
  });
  // IDs must be unique: they label particles through the run (here within the share).
  std::vector<std::uint64_t> sorted = ids;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
    throw UserError("'" + path + "': ParticleIDs are not unique");
  for (double m : p.mass)
    if (!(m > 0)) throw UserError("'" + path + "': PartType0/Masses must be positive");
  return p;
}
}  // namespace

template <int D>
Particles<D> read_snapshot(const std::string& path, const UnitSystem* code_units, SnapshotMeta& meta, h5::RowShare share) {
  h5::isolate_library_crashes(path, [&] {
    SnapshotMeta m;
    read_snapshot_unisolated<D>(path, code_units, m, share);
  });
  return read_snapshot_unisolated<D>(path, code_units, meta, share);
}

int snapshot_dimension(const std::string& path, int unrecorded) {
  auto read = [&] {
    h5::Handle file = h5::open_file_readonly(path);
    h5::Handle header = h5::open_group(file, "Header", path);
    if (!h5::has_attr(header, "SimulationDimension")) return unrecorded;
    const double d = h5::read_attr_double(header, "SimulationDimension", path);
    if (d != 2 && d != 3) throw UserError("'" + path + "': Header/SimulationDimension must be 2 or 3");
    return static_cast<int>(d);
  };
  return h5::read_isolated(path, read);
}

std::string snapshot_run_id(const std::string& path) {
  auto read = [&] {
    h5::Handle file = h5::open_file_readonly(path);
    h5::Handle header = h5::open_group(file, "Header", path);
    return h5::has_attr(header, "RunID") ? h5::read_attr_string(header, "RunID", path) : std::string();
  };
  return h5::read_isolated(path, read);
}

template double snapshot_box_size(const Particles<2>&);
template double snapshot_box_size(const Particles<3>&);
template void write_snapshot_share(const std::string&, const Communicator&, std::size_t, std::size_t, const Particles<2>&,
                                   const std::vector<std::size_t>&, const SnapshotMeta&);
template void write_snapshot_share(const std::string&, const Communicator&, std::size_t, std::size_t, const Particles<3>&,
                                   const std::vector<std::size_t>&, const SnapshotMeta&);
template void write_snapshot(const std::string&, const Particles<2>&, const SnapshotMeta&);
template void write_snapshot(const std::string&, const Particles<3>&, const SnapshotMeta&);
template Particles<2> read_snapshot(const std::string&, const UnitSystem*, SnapshotMeta&, h5::RowShare);
template Particles<3> read_snapshot(const std::string&, const UnitSystem*, SnapshotMeta&, h5::RowShare);

}  // namespace sphdisk
