#include "io/checkpoint.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string_view>
#include <type_traits>
#include <utility>

#include "core/build_info.hpp"
#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/hdf5_util.hpp"
#include "io/snapshot.hpp"

namespace sphdisk {

namespace {

// Format 1 (before 2026-11-29): one FNV-1a hash run over all fields in order; no longer read
// (docs/design.md, "Modes kept and retired"), refused with a one-line error.
// Format 2: the row-sum checksum below, which ranks can compute on their own rows.
// Format 3 (2026-11-30): adds the smoothing-length history (h_prev, h_prev2), which earlier files
// lack: their particles start without one, as new particles do.
// Format 4 (2026-12-03): attribute RateState; where it is 1 the kRateState fields are stored too (in
// double precision, whatever their storage), as a block-timestep run needs them to continue.
// Format 5 (2026-12-03): attribute StepState; where it is 1 the checkpoint was written inside a
// block cycle, holds the kStepState fields, and IntegratorState is the cycle's state. Attribute
// AbsentFields: the field flags of the fields its particles did not have (Particles::absent_fields).
// Format 6 (2026-12-04): the fields a run does not use may be absent too (kEnergyOnly without an
// energy equation, kForceCorrectionOnly without the force correction: core/particles.hpp).
// Format 7 (2026-12-04): the mixed correction's shift (correction_shift, a kRateState field absent
// where unused: kMixedCorrectionOnly), which earlier files never hold: they were written by runs
// without it (their configurations name the linear or no gradient correction).
// Format 8 (2026-12-05): the artificial viscosity's limiter and signal speeds (kRateState fields,
// absent where unused: kArtificialViscosityOnly), which earlier files never hold.
// Format 9 (2026-12-05): each particle's artificial-viscosity alpha (av_alpha, kCheckpoint, absent
// where unused), which a format-8 file with the artificial viscosity lacks: its run had one alpha
// for all (resumed without the switch, app/simulation.cpp), set anew on resume (app/runner.cpp).
// Format 10 (2026-12-05): the scatter density (scatter_density, a kRateState field absent where
// unused: kScatterDensityOnly), which earlier files never hold: their runs compared summed densities.
// Format 11 (2026-12-07): the run's identity (attribute RunID), which its resumes keep whatever
// settings they override (earlier files' runs take it from their first snapshot), and a run
// from a file's initial mass (InitialMass), both in the checksum where present.
constexpr long long kFormatVersion = 11;
constexpr long long kOldestFormatRead = 2;

// The format that added a checkpoint field to files that could have held it before (0: none).
long long format_that_added(std::string_view field) {
  if (field == "h_prev" || field == "h_prev2") return 3;
  if (field == "av_alpha") return 9;
  return 0;
}

// FNV-1a, 64 bit: cheap and order-sensitive, enough to detect corruption (not tampering).
struct Checksum {
  std::uint64_t h = 1469598103934665603ull;
  void add(const void* data, std::size_t bytes) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < bytes; ++k) h = (h ^ b[k]) * 1099511628211ull;
  }
  void add(double v) { add(&v, sizeof v); }
  void add(long long v) { add(&v, sizeof v); }
  void add(std::uint64_t v) { add(&v, sizeof v); }
};

// The number type of a field's entries (double, or float for kReduced fields in a build with
// single-precision fields) and how many of them an entry holds.
template <class T>
struct EntryOf {
  using Number = T;
};
template <class T>
  requires std::is_class_v<T>
struct EntryOf<T> {
  using Number = std::remove_cvref_t<decltype(std::declval<T>().c[0])>;
};
template <class T>
using NumberOf = typename EntryOf<T>::Number;
template <class T>
constexpr std::size_t components() {
  return sizeof(T) / sizeof(NumberOf<T>);
}

std::uint64_t state_hash(const RunState& s) {
  Checksum c;
  c.add(s.time);
  c.add(s.step);
  c.add(s.next_output);
  c.add(s.accreted_mass);
  c.add(s.accreted_angular_momentum);
  c.add(s.smoothing_length);
  for (double v : s.integrator) c.add(v);
  if (s.rate_state) c.add(1LL);  // (absent from earlier formats' hashes)
  if (s.step_state) c.add(2LL);  // (absent from formats before 5)
  c.add(s.config_toml.data(), s.config_toml.size());
  if (!s.run_id.empty()) c.add(s.run_id.data(), s.run_id.size());  // (absent before format 11)
  if (s.initial_mass > 0) c.add(s.initial_mass);                      // (absent before format 11)
  return c.h;
}

// Format 2: the sum (mod 2^64) over checkpoint fields f and rows k of FNV-1a(f, k, row k's bytes).
// Each row enters with its field and index, so swapped or shifted rows are caught, and the sum of
// any split of the rows into shares is the same.
template <class T>
std::uint64_t row_sum(std::size_t field, std::size_t first_row, const std::vector<T>& rows) {
  std::uint64_t sum = 0;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    Checksum c;
    c.add(static_cast<std::uint64_t>(field));
    c.add(static_cast<std::uint64_t>(first_row + k));
    c.add(&rows[k], sizeof(T));
    sum += c.h;
  }
  return sum;
}

// Calls f(info, field, index) for each field the checkpoint of state s holds, index counting them
// in table order.
template <class P, class F>
void for_each_checkpoint_field(P& p, const RunState& s, F&& f) {
  std::size_t index = 0;
  p.for_each_field([&](const FieldInfo& info, auto& field) {
    if (info.flags & checkpoint_field_flags(s)) f(info, field, index++);
  });
}

}  // namespace

template <int D>
void write_checkpoint_share(const std::string& path, const Communicator& comm, std::size_t n, std::size_t first_row,
                            const Particles<D>& p, const RunState& s) {
  std::uint64_t sum = 0;
  for_each_checkpoint_field(p, s, [&](const FieldInfo&, const auto& field, std::size_t f) {
    sum += row_sum(f, first_row, field);
  });
  const std::uint64_t total = comm.sum(sum) + state_hash(s);  // unsigned: wraps mod 2^64 on every rank alike
  write_hdf5_atomically(path, comm, [&](hid_t file, hid_t transfer) {
    h5::Handle g = h5::create_group(file, "Checkpoint");
    h5::write_attr(g, "FormatVersion", kFormatVersion);
    h5::write_attr(g, "Dimension", static_cast<long long>(D));
    h5::write_attr(g, "SinglePrecisionFields", kSinglePrecisionFields ? 1LL : 0LL);
    h5::write_attr(g, "CodeVersion", std::string(code_version()));  // for the record; not checked on resume
    h5::write_attr(g, "Time", s.time);
    h5::write_attr(g, "Step", s.step);
    h5::write_attr(g, "NextOutput", s.next_output);
    h5::write_attr(g, "AccretedMass", s.accreted_mass);
    h5::write_attr(g, "AccretedAngularMomentum", s.accreted_angular_momentum);
    h5::write_attr(g, "SmoothingLength", s.smoothing_length);
    h5::write_attr(g, "IntegratorState", s.integrator.empty() ? std::vector<double>{0.0} : s.integrator);
    h5::write_attr(g, "IntegratorStateSize", static_cast<long long>(s.integrator.size()));
    h5::write_attr(g, "Config", s.config_toml);
    if (!s.run_id.empty()) h5::write_attr(g, "RunID", s.run_id);
    if (s.initial_mass > 0) h5::write_attr(g, "InitialMass", s.initial_mass);
    h5::write_attr(g, "NumParticles", static_cast<long long>(n));
    h5::write_attr(g, "Checksum", std::to_string(total));
    h5::write_attr(g, "RateState", s.rate_state ? 1LL : 0LL);
    h5::write_attr(g, "StepState", s.step_state ? 1LL : 0LL);
    h5::write_attr(g, "AbsentFields", static_cast<long long>(p.absent_fields()));
    h5::Handle parts = h5::create_group(file, "Particles");
    for_each_checkpoint_field(p, s, [&](const FieldInfo& info, const auto& field, std::size_t) {
      using T = typename std::decay_t<decltype(field)>::value_type;
      const bool ids = std::is_same_v<T, std::uint64_t>;
      const h5::Handle ds = h5::create_dataset(parts, std::string(info.name), ids, n, components<T>());
      if constexpr (std::is_same_v<T, std::uint64_t>) {
        h5::write_rows(ds, field.data(), first_row, field.size(), transfer);
      } else if constexpr (std::is_same_v<NumberOf<T>, double>) {
        h5::write_rows(ds, reinterpret_cast<const double*>(field.data()), first_row, field.size(), components<T>(), transfer);
      } else {  // single-precision storage, widened exactly
        const auto* from = reinterpret_cast<const NumberOf<T>*>(field.data());
        const std::vector<double> wide(from, from + field.size() * components<T>());
        h5::write_rows(ds, wide.data(), first_row, field.size(), components<T>(), transfer);
      }
    });
  });
}

template <int D>
void write_checkpoint(const std::string& path, const Particles<D>& p, const RunState& s) {
  write_checkpoint_share(path, Communicator::self(), p.size(), 0, p, s);
}

namespace {

template <int D>
struct ReadShare {
  Particles<D> particles;
  long long version = 0;
  std::uint64_t sum = 0;  // format 2: this share's row sum
  std::string checksum;   // as stored
};

template <int D>
ReadShare<D> read_checkpoint_unisolated(const std::string& path, RunState& s, h5::RowShare share) {
  h5::Handle file = h5::open_file_readonly(path);
  h5::Handle g = h5::open_group(file, "Checkpoint", path);
  auto num = [&](const char* name) { return h5::read_attr_double(g, name, path); };
  ReadShare<D> out;
  const double version = num("FormatVersion");  // compared as stored: a corrupt value may be NaN
  const bool known = version >= 1 && version <= static_cast<double>(kFormatVersion) && version == std::floor(version);
  if (!known) throw UserError("'" + path + "' is a checkpoint of another format version");
  if (num("Dimension") != D)
    throw UserError("'" + path + "' is a checkpoint of a run in another dimension than " + std::to_string(D) + "D");
  out.version = static_cast<long long>(version);
  if (out.version < kOldestFormatRead)
    throw UserError("'" + path + "' is a checkpoint of format " + std::to_string(out.version) +
                    " (written before 2026-11-29), which this sphdisk no longer reads; continue it with the sphdisk that "
                    "wrote it (its attribute CodeVersion names the commit) or start the run again");
  // A run continues bit for bit only in a build of the same field precision (core/particles.hpp);
  // checkpoints without the attribute come from before the option, all double.
  const bool single = h5::exists_attr(g, "SinglePrecisionFields") && num("SinglePrecisionFields") != 0;
  if (single != kSinglePrecisionFields)
    throw UserError("'" + path + "' was written by a build " + (single ? "with" : "without") +
                    " single-precision fields; resume it with that build (" +
                    (single ? "cmake --preset single: build/single/sphdisk" : "cmake --preset release: build/release/sphdisk") + ")");
  auto count = [&](const char* name) {  // a non-negative integer stored as a number
    const double v = num(name);
    if (!(v >= 0 && v <= 9.0e15 && v == std::floor(v)))
      throw UserError("'" + path + "': checkpoint attribute '" + std::string(name) + "' is not a valid count (corrupt file?)");
    return static_cast<long long>(v);
  };
  s.time = num("Time");
  s.step = count("Step");
  s.next_output = count("NextOutput");
  s.accreted_mass = num("AccretedMass");
  s.accreted_angular_momentum = num("AccretedAngularMomentum");
  s.smoothing_length = num("SmoothingLength");
  s.integrator = h5::read_attr_doubles(g, "IntegratorState", path);
  const double state_size = num("IntegratorStateSize");
  if (!(state_size >= 0 && state_size <= static_cast<double>(s.integrator.size())))
    throw UserError("'" + path + "': checkpoint integrator state is inconsistent (corrupt file?)");
  s.integrator.resize(static_cast<std::size_t>(state_size));
  s.config_toml = h5::read_attr_string(g, "Config", path);
  s.run_id = out.version >= 11 && h5::exists_attr(g, "RunID") ? h5::read_attr_string(g, "RunID", path) : "";
  s.initial_mass = out.version >= 11 && h5::exists_attr(g, "InitialMass") ? num("InitialMass") : 0.0;
  if (!(s.initial_mass >= 0)) throw UserError("'" + path + "': checkpoint attribute 'InitialMass' is not valid (corrupt file?)");
  s.rate_state = out.version >= 4 && num("RateState") != 0;
  s.step_state = out.version >= 5 && num("StepState") != 0;
  // The fields its writer left out (core/particles.hpp): neither stored nor counted in the checksum.
  const unsigned may_be_absent =
      kStepState | kEnergyStepState | (out.version >= 6 ? unsigned{kEnergyOnly | kForceCorrectionOnly} : 0u) |
      (out.version >= 7 ? unsigned{kMixedCorrectionOnly} : 0u) | (out.version >= 8 ? unsigned{kArtificialViscosityOnly} : 0u) |
      (out.version >= 10 ? unsigned{kScatterDensityOnly} : 0u);
  const double absent = out.version >= 5 ? num("AbsentFields") : 0.0;
  if (!(absent >= 0 && absent <= may_be_absent && absent == std::floor(absent)) ||
      (static_cast<unsigned>(absent) & ~may_be_absent) != 0)
    throw UserError("'" + path + "': checkpoint attribute 'AbsentFields' is not valid (corrupt file?)");
  const double n_attr = num("NumParticles");
  out.checksum = h5::read_attr_string(g, "Checksum", path);

  const h5::RowShare read = share;
  h5::Handle parts = h5::open_group(file, "Particles", path);
  std::size_t n = 0;
  const std::size_t rows_read = h5::read_dataset_u64(parts, "id", path, n, read).size();  // size-checked by the reader
  if (static_cast<double>(n) != n_attr) throw UserError("'" + path + "': checkpoint particle count does not match its datasets");
  Particles<D>& p = out.particles;
  // Files before format 7 never hold the mixed correction's shift (before 10 the scatter density).
  p.set_absent_fields(static_cast<unsigned>(absent) | (out.version < 7 ? unsigned{kMixedCorrectionOnly} : 0u) |
                      (out.version < 8 ? unsigned{kArtificialViscosityOnly} : 0u) |
                      (out.version < 10 ? unsigned{kScatterDensityOnly} : 0u));
  p.resize(rows_read);
  for_each_checkpoint_field(p, s, [&](const FieldInfo& info, auto& field, std::size_t f) {
    using T = typename std::decay_t<decltype(field)>::value_type;
    const std::string name(info.name);
    if (out.version < format_that_added(name) && !h5::exists(parts, name)) {
      field.assign(rows_read, {});  // no history; no alpha of its own
      return;
    }
    std::size_t rows = 0, cols = 1;
    if constexpr (std::is_same_v<T, std::uint64_t>) {
      field = h5::read_dataset_u64(parts, name, path, rows, read);
    } else {
      const std::vector<double> raw = h5::read_dataset_doubles(parts, name, path, rows, cols, read);
      if (cols != components<T>() || raw.size() != rows_read * cols)
        throw UserError("'" + path + "': checkpoint dataset '" + name + "' has the wrong shape");
      if constexpr (std::is_same_v<NumberOf<T>, double>) {
        if (!raw.empty()) std::memcpy(static_cast<void*>(field.data()), raw.data(), raw.size() * sizeof(double));
      } else {  // stored widened from single precision: narrowed back exactly
        auto* to = reinterpret_cast<NumberOf<T>*>(field.data());
        for (std::size_t k = 0; k < raw.size(); ++k) to[k] = static_cast<NumberOf<T>>(raw[k]);
      }
    }
    if (rows != n || field.size() != rows_read)
      throw UserError("'" + path + "': checkpoint dataset '" + name + "' has the wrong size");
    out.sum += row_sum(f, share.first(n), field);
  });
  return out;
}

}  // namespace

int checkpoint_dimension(const std::string& path) {
  auto read = [&] {
    h5::Handle file = h5::open_file_readonly(path);
    h5::Handle g = h5::open_group(file, "Checkpoint", path);
    const double d = h5::read_attr_double(g, "Dimension", path);
    if (d != 2 && d != 3) throw UserError("'" + path + "': checkpoint attribute 'Dimension' is not 2 or 3 (corrupt file?)");
    return static_cast<int>(d);
  };
  return h5::read_isolated(path, read);
}

template <int D>
Particles<D> read_checkpoint(const std::string& path, RunState& s, const Communicator& comm) {
  const h5::RowShare share{static_cast<std::size_t>(comm.rank()), static_cast<std::size_t>(comm.size())};
  ReadShare<D> got;
  run_collectively(comm, [&] {
    h5::isolate_library_crashes(path, [&] {
      RunState tmp;
      read_checkpoint_unisolated<D>(path, tmp, share);
    });
    got = read_checkpoint_unisolated<D>(path, s, share);
  });
  if (std::to_string(comm.sum(got.sum) + state_hash(s)) != got.checksum)
    throw UserError("checkpoint '" + path + "' is corrupt (checksum mismatch); use an earlier copy or restart the run");
  return std::move(got.particles);
}

template void write_checkpoint_share(const std::string&, const Communicator&, std::size_t, std::size_t, const Particles<2>&,
                                     const RunState&);
template void write_checkpoint_share(const std::string&, const Communicator&, std::size_t, std::size_t, const Particles<3>&,
                                     const RunState&);
template void write_checkpoint(const std::string&, const Particles<2>&, const RunState&);
template void write_checkpoint(const std::string&, const Particles<3>&, const RunState&);
template Particles<2> read_checkpoint(const std::string&, RunState&, const Communicator&);
template Particles<3> read_checkpoint(const std::string&, RunState&, const Communicator&);

}  // namespace sphdisk
