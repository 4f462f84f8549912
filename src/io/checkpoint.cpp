#include "io/checkpoint.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/hdf5_util.hpp"
#include "io/snapshot.hpp"

namespace sphdisk {

namespace {

constexpr int kDim = 2;
constexpr long long kFormatVersion = 1;

// FNV-1a, 64 bit: cheap and order-sensitive, enough to detect corruption (not tampering).
struct Checksum {
  std::uint64_t h = 1469598103934665603ull;
  void add(const void* data, std::size_t bytes) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < bytes; ++k) h = (h ^ b[k]) * 1099511628211ull;
  }
  void add(double v) { add(&v, sizeof v); }
  void add(long long v) { add(&v, sizeof v); }
};

template <class T>
std::size_t components() {
  if constexpr (std::is_same_v<T, Vec<kDim>>) return kDim;
  else if constexpr (std::is_same_v<T, Mat<kDim>>) return kDim * kDim;
  else return 1;
}

void add_state(Checksum& c, const RunState& s) {
  c.add(s.time);
  c.add(s.step);
  c.add(s.next_output);
  c.add(s.accreted_mass);
  c.add(s.accreted_angular_momentum);
  c.add(s.smoothing_length);
  for (double v : s.integrator) c.add(v);
  c.add(s.config_toml.data(), s.config_toml.size());
}

}  // namespace

void write_checkpoint_blocks(const std::string& path, std::size_t n, const RunState& s, std::size_t blocks,
                             const CheckpointBlock& block) {
  Checksum sum;
  add_state(sum, s);
  write_hdf5_atomically(path, [&](hid_t file) {
    h5::Handle g = h5::create_group(file, "Checkpoint");
    h5::write_attr(g, "FormatVersion", kFormatVersion);
    h5::write_attr(g, "Dimension", static_cast<long long>(kDim));
    h5::write_attr(g, "Time", s.time);
    h5::write_attr(g, "Step", s.step);
    h5::write_attr(g, "NextOutput", s.next_output);
    h5::write_attr(g, "AccretedMass", s.accreted_mass);
    h5::write_attr(g, "AccretedAngularMomentum", s.accreted_angular_momentum);
    h5::write_attr(g, "SmoothingLength", s.smoothing_length);
    h5::write_attr(g, "IntegratorState", s.integrator.empty() ? std::vector<double>{0.0} : s.integrator);
    h5::write_attr(g, "IntegratorStateSize", static_cast<long long>(s.integrator.size()));
    h5::write_attr(g, "Config", s.config_toml);
    h5::write_attr(g, "NumParticles", static_cast<long long>(n));
    h5::Handle parts = h5::create_group(file, "Particles");
    const Particles<kDim> none;
    none.for_each_field([&](const FieldInfo& info, const auto& empty) {
      if (!(info.flags & kCheckpoint)) return;
      using T = typename std::decay_t<decltype(empty)>::value_type;
      const std::string name(info.name);
      const bool ids = std::is_same_v<T, std::uint64_t>;
      h5::Handle ds = h5::create_dataset(parts, name, ids, n, components<T>());
      std::size_t row = 0;
      for (std::size_t b = 0; b < blocks; ++b) {  // field-major, as the checksum runs
        const Particles<kDim>& q = block(info.name, b);
        const auto& field = [&]() -> const std::vector<T>& {
          const std::vector<T>* f = nullptr;
          q.for_each_field([&](const FieldInfo& i, const auto& v) {
            if constexpr (std::is_same_v<std::decay_t<decltype(v)>, std::vector<T>>)
              if (i.name == info.name) f = &v;
          });
          return *f;
        }();
        sum.add(field.data(), field.size() * sizeof(T));
        if constexpr (std::is_same_v<T, std::uint64_t>)
          h5::write_rows(ds, field.data(), row, field.size());
        else
          h5::write_rows(ds, reinterpret_cast<const double*>(field.data()), row, field.size(), components<T>());
        row += field.size();
      }
      if (row != n) throw UserError("checkpoint blocks hold " + std::to_string(row) + " particles, not " + std::to_string(n));
    });
    h5::write_attr(g, "Checksum", std::to_string(sum.h));
  });
}

void write_checkpoint(const std::string& path, const Particles<2>& p, const RunState& s) {
  write_checkpoint_blocks(path, p.size(), s, 1, [&p](std::string_view, std::size_t) -> const Particles<2>& { return p; });
}

namespace {
Particles<2> read_checkpoint_unisolated(const std::string& path, RunState& s) {
  h5::Handle file = h5::open_file_readonly(path);
  h5::Handle g = h5::open_group(file, "Checkpoint", path);
  auto num = [&](const char* name) { return h5::read_attr_double(g, name, path); };
  if (num("FormatVersion") != static_cast<double>(kFormatVersion) || num("Dimension") != kDim)
    throw UserError("'" + path + "' is a checkpoint of another format version or dimension");
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
  const double n_attr = num("NumParticles");

  Checksum sum;
  add_state(sum, s);
  h5::Handle parts = h5::open_group(file, "Particles", path);
  const std::size_t n = h5::read_dataset_u64(parts, "id", path).size();  // size-checked by the reader
  if (static_cast<double>(n) != n_attr) throw UserError("'" + path + "': checkpoint particle count does not match its datasets");
  Particles<2> p;
  p.resize(n);
  p.for_each_field([&](const FieldInfo& info, auto& field) {
    if (!(info.flags & kCheckpoint)) return;
    using T = typename std::decay_t<decltype(field)>::value_type;
    const std::string name(info.name);
    if constexpr (std::is_same_v<T, std::uint64_t>) {
      field = h5::read_dataset_u64(parts, name, path);
    } else {
      std::size_t rows, cols;
      const std::vector<double> raw = h5::read_dataset_doubles(parts, name, path, rows, cols);
      if (rows != n || cols != components<T>()) throw UserError("'" + path + "': checkpoint dataset '" + name + "' has the wrong shape");
      std::memcpy(static_cast<void*>(field.data()), raw.data(), raw.size() * sizeof(double));
    }
    if (field.size() != n) throw UserError("'" + path + "': checkpoint dataset '" + name + "' has the wrong size");
    sum.add(field.data(), field.size() * sizeof(T));
  });
  if (h5::read_attr_string(g, "Checksum", path) != std::to_string(sum.h))
    throw UserError("checkpoint '" + path + "' is corrupt (checksum mismatch); use an earlier copy or restart the run");
  return p;
}
}  // namespace

Particles<2> read_checkpoint(const std::string& path, RunState& s) {
  h5::isolate_library_crashes(path, [&] {
    RunState tmp;
    read_checkpoint_unisolated(path, tmp);
  });
  return read_checkpoint_unisolated(path, s);
}

}  // namespace sphdisk
