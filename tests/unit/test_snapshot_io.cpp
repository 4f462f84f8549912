// HDF5 snapshots: round trip of every snapshot field, unit conversion on read, and clear errors
// for missing, truncated and foreign files.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <map>
#include <fstream>

#include "core/error.hpp"
#include "io/snapshot.hpp"
#include "test_helpers.hpp"

using namespace sphdisk;
namespace fs = std::filesystem;

namespace {
fs::path temp_dir() {
  fs::path d = fs::temp_directory_path() / ("sphdisk_io_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}
}  // namespace

TEST(Snapshot, RoundTripKeepsEveryFieldBitForBit) {
  auto p = test::random_particles<2>(1000, 3, false);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.h[i] = 0.01 + 1e-5 * static_cast<double>(i);
    p.rho[i] = 1.0 + 0.5 * static_cast<double>(i % 7);
    p.u[i] = 0.25 * static_cast<double>(i % 5);
    p.acc[i] = Vec<2>{{1.0 / static_cast<double>(i + 1), -3.0}};
  }
  SnapshotMeta meta;
  meta.time = 12.5;
  meta.tau = 0.036;
  meta.viscosity = 4.7e-5;
  meta.disc_mass = 1e-10;
  meta.accreted_mass = 3e-14;
  meta.energy = true;
  meta.units = UnitSystem::from_solar(1.0, 1.0);
  meta.parameters = {{"problem.particles", "1000"}, {"output.tau", "[0.036, 0.09]"}, {"sph.kernel", "\"cubic\""}};
  const std::string path = (temp_dir() / "roundtrip.hdf5").string();
  write_snapshot(path, p, meta);
  EXPECT_FALSE(fs::exists(path + ".tmp"));

  SnapshotMeta back;
  const auto q = read_snapshot<2>(path, &meta.units, back);
  ASSERT_EQ(q.size(), p.size());
  // Written in ID order: match by ID.
  std::map<std::uint64_t, std::size_t> where;
  for (std::size_t i = 0; i < q.size(); ++i) where[q.id[i]] = i;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const std::size_t k = where.at(p.id[i]);
    EXPECT_EQ(q.pos[k], p.pos[i]);
    EXPECT_EQ(q.vel[k], p.vel[i]);
    EXPECT_EQ(q.mass[k], p.mass[i]);
    EXPECT_EQ(q.h[k], p.h[i]);
    EXPECT_EQ(q.rho[k], p.rho[i]);
    EXPECT_EQ(q.u[k], p.u[i]);
    EXPECT_EQ(q.acc[k], p.acc[i]);
  }
  EXPECT_EQ(back.time, meta.time);
  EXPECT_EQ(back.tau, meta.tau);
  EXPECT_EQ(back.accreted_mass, meta.accreted_mass);
  EXPECT_TRUE(back.energy);
  for (std::size_t i = 1; i < q.size(); ++i) EXPECT_LT(q.id[i - 1], q.id[i]);
}

TEST(Snapshot, ConvertsUnitsOnRead) {
  auto p = test::random_particles<2>(10, 4, false);
  SnapshotMeta meta;
  meta.units = UnitSystem::from_solar(2.0, 1.0);  // file: length unit 2 Rsun
  meta.time = 1.0;
  const std::string path = (temp_dir() / "units.hdf5").string();
  write_snapshot(path, p, meta);
  const UnitSystem code = UnitSystem::from_solar(1.0, 1.0);
  SnapshotMeta back;
  const auto q = read_snapshot<2>(path, &code, back);
  const double lt = meta.units.time_s / code.time_s;
  EXPECT_NEAR(back.time, lt, 1e-12 * lt);
  double sum_p = 0, sum_q = 0;
  for (std::size_t i = 0; i < p.size(); ++i) sum_p += p.pos[i][0], sum_q += q.pos[i][0];
  EXPECT_NEAR(sum_q, 2.0 * sum_p, 1e-12 * std::abs(sum_p) * 2);
}

TEST(Snapshot, MissingTruncatedAndForeignFilesGiveUserErrors) {
  SnapshotMeta meta;
  EXPECT_THROW(read_snapshot<2>("/nonexistent/snap.hdf5", nullptr, meta), UserError);
  const fs::path dir = temp_dir();
  {
    std::ofstream f(dir / "garbage.hdf5");
    f << "this is not hdf5";
  }
  EXPECT_THROW(read_snapshot<2>((dir / "garbage.hdf5").string(), nullptr, meta), UserError);
  // Truncate a valid file to half its size.
  auto p = test::random_particles<2>(5000, 5, false);
  const std::string good = (dir / "good.hdf5").string();
  write_snapshot(good, p, SnapshotMeta{});
  fs::copy_file(good, dir / "cut.hdf5", fs::copy_options::overwrite_existing);
  fs::resize_file(dir / "cut.hdf5", fs::file_size(good) / 2);
  EXPECT_THROW(read_snapshot<2>((dir / "cut.hdf5").string(), nullptr, meta), UserError);
}

TEST(Snapshot, UnwritableDirectoryIsAUserError) {
  auto p = test::random_particles<2>(10, 6, false);
  EXPECT_THROW(write_snapshot("/nonexistent_dir/x/snap.hdf5", p, SnapshotMeta{}), UserError);
}
