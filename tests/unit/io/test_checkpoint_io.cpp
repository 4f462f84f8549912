// Checkpoints: bit-exact round trip of particles and run state; the row-sum checksum (format 2)
// catches changed and swapped rows; files of format 1 (one FNV-1a hash over the fields in order,
// written before 2026-11-29) are refused with the way out; formats 2-7 are read.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstring>
#include <functional>
#include <filesystem>

#include "core/error.hpp"
#include "io/checkpoint.hpp"
#include "io/hdf5_util.hpp"
#include "test_helpers.hpp"

using namespace sphdisk;
namespace fs = std::filesystem;

namespace {

fs::path temp_file(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("sphdisk_ckpt_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d / name;
}

Particles<2> sample_particles() {
  auto p = test::random_particles<2>(500, 11, false);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.h[i] = 0.02 + 1e-6 * static_cast<double>(i);
    p.mass[i] = 1e-3 * static_cast<double>(1 + i % 7);  // distinct neighbours: a swap changes the rows
    p.u[i] = 0.5 * static_cast<double>(i % 5);
    p.du_dt[i] = -1e-3 * static_cast<double>(i % 3);
    p.acc[i] = Vec<2>{{1e-3 * static_cast<double>(i), -2e-3}};
    p.h_prev[i] = 0.99 * p.h[i];
    p.h_prev2[i] = i % 5 ? 0.98 * p.h[i] : 0.0;
  }
  return p;
}

RunState sample_state() {
  RunState s;
  s.time = 0.123;
  s.step = 77;
  s.next_output = 2;
  s.accreted_mass = 1e-4;
  s.accreted_angular_momentum = 2e-4;
  s.smoothing_length = 0.03;
  s.integrator = {0.5, 0.25};
  s.config_toml = "[problem]\nparticles = 500\n";
  return s;
}

template <class T>
void expect_same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(T)));
}

// The state of a checkpoint written inside a block cycle (its length and the ticks done).
RunState state_inside_a_cycle() {
  RunState s = sample_state();
  s.rate_state = s.step_state = true;
  s.integrator = {0.125, 4096.0};
  return s;
}

// p and s written to a checkpoint at path and read back (the state into r).
Particles<2> round_trip(const Particles<2>& p, const RunState& s, const fs::path& path, RunState& r) {
  write_checkpoint(path.string(), p, s);
  return read_checkpoint<2>(path.string(), r);
}

// Changes entries of a file's dataset of `entries` doubles or 64-bit integers in place: read whole,
// change(all), written back.
template <class T>
void change_entries(const fs::path& path, const char* dataset, std::size_t entries,
                    const std::function<void(std::vector<T>&)>& change) {
  const hid_t type = std::is_same_v<T, double> ? H5T_NATIVE_DOUBLE : H5T_NATIVE_UINT64;
  h5::Handle f(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
  h5::Handle ds(H5Dopen2(f, dataset, H5P_DEFAULT), H5Dclose);
  std::vector<T> all(entries);
  ASSERT_GE(H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, all.data()), 0);
  change(all);
  ASSERT_GE(H5Dwrite(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, all.data()), 0);
}

void set_attrs(const fs::path& path, long long version, const std::string& checksum) {
  h5::Handle f(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
  h5::Handle g(H5Gopen2(f, "Checkpoint", H5P_DEFAULT), H5Gclose);
  h5::write_attr(g, "FormatVersion", version);
  h5::write_attr(g, "Checksum", checksum);
}

void overwrite_mass_row(const fs::path& path, std::size_t row, double value) {
  h5::Handle f(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
  h5::Handle ds(H5Dopen2(f, "Particles/mass", H5P_DEFAULT), H5Dclose);
  h5::write_rows(ds, &value, row, 1, 1);
}

}  // namespace

TEST(Checkpoint, RoundTripKeepsParticlesAndStateBitForBit) {
  const Particles<2> p = sample_particles();
  const RunState s = sample_state();
  const fs::path path = temp_file("round_trip.h5");
  write_checkpoint(path.string(), p, s);
  RunState r;
  const Particles<2> q = read_checkpoint<2>(path.string(), r);
  std::size_t compared = 0;  // every checkpoint field of the table, whatever it holds
  p.for_each_field([&](const FieldInfo& info, const auto& field) {
    if (!(info.flags & kCheckpoint)) return;
    q.for_each_field([&](const FieldInfo& other, const auto& read) {
      if constexpr (std::is_same_v<decltype(field), decltype(read)>)
        if (other.name == info.name) expect_same_bits(field, read), ++compared;
    });
  });
  EXPECT_EQ(compared, 11u);  // id, mass, pos, vel, u, h, acc, du_dt, h_prev, h_prev2, av_alpha
  EXPECT_EQ(r.time, s.time);
  EXPECT_EQ(r.step, s.step);
  EXPECT_EQ(r.next_output, s.next_output);
  EXPECT_EQ(r.integrator, s.integrator);
  EXPECT_EQ(r.config_toml, s.config_toml);
}

// Block timesteps need the last evaluation's density, volume, stress and moment correction to
// continue (kRateState), and a checkpoint written inside a block cycle the particles' steps in it
// (kStepState: the 64-bit step ticks whole, the kicked velocity and energy) and the cycle's state:
// with RunState::rate_state and step_state they round-trip bit for bit (single-precision storage
// too, widened in the file), they enter the checksum, and without those flags they are not written.
TEST(Checkpoint, RateAndStepStateRoundTripBitForBitWhenAskedFor) {
  Particles<2> p = sample_particles();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double x = 1.0 + 1e-3 * static_cast<double>(i);
    p.rho[i] = static_cast<ReducedReal>(x / 3.0);
    p.volume[i] = p.mass[i] / (x / 3.0);
    for (std::size_t c = 0; c < 4; ++c) {
      p.stress[i].c[c] = static_cast<ReducedReal>(x / static_cast<double>(7 + c));
      p.correction[i].c[c] = static_cast<ReducedReal>(-x / static_cast<double>(11 + c));
    }
    p.step_ticks[i] = (std::uint64_t{3 * i + 1} << 32) | (std::uint64_t{1} << (i % 20));
    p.v_kick[i] = {1.0 / (x + 3.0), -2.0 / (x + 7.0)};
    p.u_kick[i] = 5.0 / (x + 11.0);
  }
  RunState s = state_inside_a_cycle();
  const fs::path path = temp_file("rate_state.h5");
  RunState r;
  const Particles<2> q = round_trip(p, s, path, r);
  EXPECT_TRUE(r.rate_state);
  EXPECT_TRUE(r.step_state);
  EXPECT_EQ(r.integrator, s.integrator);
  expect_same_bits(p.rho, q.rho);
  expect_same_bits(p.volume, q.volume);
  expect_same_bits(p.stress, q.stress);
  expect_same_bits(p.correction, q.correction);
  expect_same_bits(p.pos, q.pos);
  EXPECT_EQ(p.step_ticks, q.step_ticks);
  expect_same_bits(p.v_kick, q.v_kick);
  expect_same_bits(p.u_kick, q.u_kick);
  // a changed stress entry or step start fails the checksum
  change_entries<double>(path, "Particles/stress", p.size() * 4, [](std::vector<double>& all) { all[4 * 17 + 1] *= 2.0; });
  EXPECT_THROW(read_checkpoint<2>(path.string(), r), UserError);
  write_checkpoint(path.string(), p, s);
  change_entries<std::uint64_t>(path, "Particles/step_ticks", p.size(),
                                [](std::vector<std::uint64_t>& all) { all[9] += std::uint64_t{1} << 32; });
  EXPECT_THROW(read_checkpoint<2>(path.string(), r), UserError);

  const auto holds = [&](const char* dataset) {
    h5::Handle f(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
    return h5::exists(f, dataset);
  };
  s.step_state = false;
  const Particles<2> between_steps = round_trip(p, s, path, r);
  EXPECT_FALSE(r.step_state);
  EXPECT_TRUE(r.rate_state);
  EXPECT_EQ(between_steps.step_ticks[5], 0u);
  EXPECT_FALSE(holds("Particles/v_kick"));
  EXPECT_TRUE(holds("Particles/stress"));
  s.rate_state = false;
  const Particles<2> without = round_trip(p, s, path, r);
  EXPECT_FALSE(r.rate_state);
  EXPECT_EQ(without.rho[5], ReducedReal{0});
  EXPECT_FALSE(holds("Particles/stress"));
}

// Fields a run leaves out (Particles::absent_fields: block steps' energy state without an energy
// equation) are neither stored nor expected, and the read particles leave them out too.
TEST(Checkpoint, AbsentFieldsAreNeitherStoredNorExpected) {
  Particles<2> p = sample_particles();
  p.set_absent_fields(kEnergyStepState);
  const fs::path path = temp_file("absent.h5");
  RunState r;
  const Particles<2> q = round_trip(p, state_inside_a_cycle(), path, r);
  EXPECT_EQ(q.absent_fields(), unsigned{kEnergyStepState});
  EXPECT_TRUE(q.u_kick.empty());
  EXPECT_EQ(q.v_kick.size(), p.size());
  expect_same_bits(p.pos, q.pos);
  h5::Handle f(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  EXPECT_FALSE(h5::exists(f, "Particles/u_kick"));
  EXPECT_TRUE(h5::exists(f, "Particles/v_kick"));
}

// The ring's run (no energy equation, no force correction, block steps) leaves out u, du_dt, u_kick
// and the moment correction (core/particles.hpp, unused_fields): its checkpoints neither store nor
// expect them, and an earlier format, which always had them, may not claim them absent.
TEST(Checkpoint, FieldsTheRunDoesNotUseAreNeitherStoredNorExpected) {
  Particles<2> p = sample_particles();
  p.set_absent_fields(unused_fields(true, false, false, false, false, false));
  const fs::path path = temp_file("unused.h5");
  RunState r;
  const Particles<2> q = round_trip(p, state_inside_a_cycle(), path, r);  // (with the rate state: stress, correction)
  EXPECT_EQ(q.absent_fields(), p.absent_fields());
  EXPECT_TRUE(q.u.empty() && q.du_dt.empty() && q.u_kick.empty() && q.correction.empty());
  expect_same_bits(p.stress, q.stress);
  expect_same_bits(p.v_kick, q.v_kick);
  {
    h5::Handle f(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
    for (const char* name : {"Particles/u", "Particles/du_dt", "Particles/u_kick", "Particles/correction"})
      EXPECT_FALSE(h5::exists(f, name)) << name;
    EXPECT_TRUE(h5::exists(f, "Particles/stress"));
  }
  set_attrs(path, 5, std::to_string(0));
  try {
    read_checkpoint<2>(path.string(), r);
    ADD_FAILURE() << "a format-5 checkpoint without u was accepted";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("'AbsentFields' is not valid"), std::string::npos) << e.what();
  }
}

// The mixed gradient correction's shift (correction_shift, format 7) round-trips where a run uses it;
// a format-6 file, which never held it, reads without it, and may not claim it absent (256 was no
// flag then). The format-6 file is this writer's file of a run without the shift, with the two
// attributes that differ set to their format-6 values (neither is in the checksum).
TEST(Checkpoint, TheMixedCorrectionsShiftRoundTripsAndFormatSixFilesLackIt) {
  Particles<2> p = sample_particles();
  p.set_absent_fields(unused_fields(true, false, true, true, false, false));
  for (std::size_t i = 0; i < p.size(); ++i) p.correction_shift[i] = Vec<2>{{0.1 * static_cast<double>(i), -1.0}};
  const fs::path path = temp_file("shift.h5");
  RunState r;
  const Particles<2> q = round_trip(p, state_inside_a_cycle(), path, r);
  expect_same_bits(p.correction_shift, q.correction_shift);

  Particles<2> linear = sample_particles();
  linear.set_absent_fields(unused_fields(true, false, true, false, false, false));
  write_checkpoint(path.string(), linear, state_inside_a_cycle());
  const auto set_format6 = [&](long long absent) {
    h5::Handle f(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
    h5::Handle g(H5Gopen2(f, "Checkpoint", H5P_DEFAULT), H5Gclose);
    h5::write_attr(g, "FormatVersion", 6LL);
    h5::write_attr(g, "AbsentFields", absent);
  };
  set_format6(static_cast<long long>(linear.absent_fields() &
                                    ~unsigned{kMixedCorrectionOnly | kArtificialViscosityOnly | kScatterDensityOnly}));
  const Particles<2> old = read_checkpoint<2>(path.string(), r);
  EXPECT_TRUE(old.correction_shift.empty());
  expect_same_bits(linear.correction, old.correction);
  // A format-6 file cannot have left out what later formats added: the mixed correction's shift
  // (flag 256, format 7) and the scatter density (flag 8192, format 10).
  for (const unsigned flag : {unsigned{kMixedCorrectionOnly}, unsigned{kScatterDensityOnly}}) {
    ASSERT_NE(linear.absent_fields() & flag, 0u);
    set_format6(static_cast<long long>(linear.absent_fields() &
                                       ~(unsigned{kMixedCorrectionOnly | kArtificialViscosityOnly | kScatterDensityOnly} & ~flag)));
    try {
      read_checkpoint<2>(path.string(), r);
      ADD_FAILURE() << "a format-6 checkpoint claiming flag " << flag << " absent was accepted";
    } catch (const UserError& e) {
      EXPECT_NE(std::string(e.what()).find("'AbsentFields' is not valid"), std::string::npos) << e.what();
    }
  }
}

TEST(Checkpoint, ChangedOrSwappedRowsFailTheChecksum) {
  const Particles<2> p = sample_particles();
  const fs::path path = temp_file("swapped.h5");
  write_checkpoint(path.string(), p, sample_state());
  // Swapping two masses keeps every sum over values; the row index in each term catches it.
  overwrite_mass_row(path, 3, p.mass[4]);
  overwrite_mass_row(path, 4, p.mass[3]);
  RunState r;
  try {
    read_checkpoint<2>(path.string(), r);
    ADD_FAILURE() << "swapped rows were accepted";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("checksum mismatch"), std::string::npos) << e.what();
  }
  overwrite_mass_row(path, 3, p.mass[3]);
  overwrite_mass_row(path, 4, p.mass[4]);
  EXPECT_NO_THROW(read_checkpoint<2>(path.string(), r));
}

// Format 1 (one hash over whole fields) is no longer read: refused with one line naming the format
// and what to do, and the file is left as it was.
TEST(Checkpoint, FormatOneFilesAreRefusedWithTheWayOut) {
  const fs::path path = temp_file("format1.h5");
  write_checkpoint(path.string(), sample_particles(), sample_state());
  set_attrs(path, 1, "12345");
  const auto before = fs::file_size(path);
  RunState r;
  try {
    read_checkpoint<2>(path.string(), r);
    ADD_FAILURE() << "a format-1 checkpoint was accepted";
  } catch (const UserError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("is a checkpoint of format 1"), std::string::npos) << what;
    EXPECT_NE(what.find("continue it with the sphdisk that wrote it"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  EXPECT_EQ(fs::file_size(path), before);
}

// A checkpoint of format 2 (fixtures/checkpoint_format2.hdf5: 300 ring particles after 3 steps,
// written by commit 7847b5b) is still read: its particles have no smoothing-length history yet, as
// new particles do. From format 3 on the history is required.
TEST(Checkpoint, FormatTwoFilesAreReadWithoutHistory) {
  const std::string fixture = std::string(SPHDISK_SOURCE_DIR) + "/tests/fixtures/checkpoint_format2.hdf5";
  RunState r;
  if (kSinglePrecisionFields) {  // written by a double build: refused (RefusesAnotherFieldPrecision)
    EXPECT_THROW(read_checkpoint<2>(fixture, r), UserError);
  } else {
    const Particles<2> q = read_checkpoint<2>(fixture, r);
    ASSERT_EQ(q.size(), 300u);
    EXPECT_EQ(r.step, 3);
    for (std::size_t i = 0; i < q.size(); ++i) {
      ASSERT_GT(q.h[i], 0.0);
      ASSERT_EQ(q.h_prev[i], 0.0);
      ASSERT_EQ(q.h_prev2[i], 0.0);
    }
  }

  const Particles<2> p = sample_particles();
  const fs::path path = temp_file("format3_without_history.h5");
  write_checkpoint(path.string(), p, sample_state());
  {
    h5::Handle f(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
    ASSERT_GE(H5Ldelete(f, "Particles/h_prev", H5P_DEFAULT), 0);
  }
  EXPECT_THROW(read_checkpoint<2>(path.string(), r), UserError);
}

// A checkpoint continues bit for bit only in a build of its field precision: another build's
// checkpoint is refused with the build to use; one without the attribute (before the option) is
// a double build's.
TEST(Checkpoint, RefusesAnotherFieldPrecision) {
  const Particles<2> p = sample_particles();
  const fs::path path = temp_file("precision.h5");
  write_checkpoint(path.string(), p, sample_state());
  RunState r;
  EXPECT_NO_THROW(read_checkpoint<2>(path.string(), r));
  {
    h5::Handle f(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
    h5::Handle g(H5Gopen2(f, "Checkpoint", H5P_DEFAULT), H5Gclose);
    h5::write_attr(g, "SinglePrecisionFields", kSinglePrecisionFields ? 0LL : 1LL);
  }
  try {
    read_checkpoint<2>(path.string(), r);
    ADD_FAILURE() << "a checkpoint of the other field precision was accepted";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("single-precision fields; resume it with that build"), std::string::npos) << e.what();
  }
  {
    h5::Handle f(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
    h5::Handle g(H5Gopen2(f, "Checkpoint", H5P_DEFAULT), H5Gclose);
    ASSERT_GE(H5Adelete(g, "SinglePrecisionFields"), 0);
  }
  if (kSinglePrecisionFields) EXPECT_THROW(read_checkpoint<2>(path.string(), r), UserError);
  else EXPECT_NO_THROW(read_checkpoint<2>(path.string(), r));
}

// Format 11: the run's identity and a file's initial mass round-trip and enter the checksum (a
// changed RunID fails it, since a resume keeps the identity it reads); a state without them writes
// neither attribute and reads back empty.
TEST(Checkpoint, RunIdentityAndInitialMassRoundTripInTheChecksum) {
  const Particles<2> p = sample_particles();
  RunState s = sample_state();
  s.run_id = "0123456789abcdef";
  s.initial_mass = 1.25e-6;
  const fs::path path = temp_file("identity.h5");
  RunState r;
  round_trip(p, s, path, r);
  EXPECT_EQ(r.run_id, s.run_id);
  EXPECT_EQ(r.initial_mass, s.initial_mass);
  {
    h5::Handle f(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
    h5::Handle g(H5Gopen2(f, "Checkpoint", H5P_DEFAULT), H5Gclose);
    H5Adelete(g, "RunID");
    h5::write_attr(g, "RunID", std::string("fedcba9876543210"));
  }
  try {
    read_checkpoint<2>(path.string(), r);
    ADD_FAILURE() << "a changed RunID was accepted";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("checksum mismatch"), std::string::npos) << e.what();
  }
  RunState plain;
  round_trip(p, sample_state(), temp_file("no_identity.h5"), plain);
  EXPECT_EQ(plain.run_id, "");
  EXPECT_EQ(plain.initial_mass, 0.0);
  h5::Handle f(H5Fopen(temp_file("no_identity.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  h5::Handle g(H5Gopen2(f, "Checkpoint", H5P_DEFAULT), H5Gclose);
  EXPECT_FALSE(h5::exists_attr(g, "RunID"));
  EXPECT_FALSE(h5::exists_attr(g, "InitialMass"));
}
