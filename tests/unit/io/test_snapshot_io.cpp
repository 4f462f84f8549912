// HDF5 snapshots: round trip of every snapshot field, the file layout yt reads (Coordinates inside
// [0, BoxSize]^3 around Header/PointMassPosition, SWIFT metadata), files without that offset, unit
// conversion on read, and clear errors for missing, truncated and foreign files.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <fstream>
#include <limits>

#include "core/error.hpp"
#include "io/hdf5_util.hpp"
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

TEST(Snapshot, RoundTripKeepsEveryFieldBitForBitAndPositionsToTheOffsetsRounding) {
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
  // Positions are stored as x + c (c = PointMassPosition) and read as (x + c) - c.
  const double c = snapshot_box_size(p) / 2;
  // Written in ID order: match by ID.
  std::map<std::uint64_t, std::size_t> where;
  for (std::size_t i = 0; i < q.size(); ++i) where[q.id[i]] = i;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const std::size_t k = where.at(p.id[i]);
    for (int d = 0; d < 2; ++d) EXPECT_EQ(q.pos[k][d], (p.pos[i][d] + c) - c);
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

namespace {
// Particles centred on the origin, as in a run (random_particles lie in [0, 1)^2), with smoothing lengths.
Particles<2> centred_particles() {
  auto p = test::random_particles<2>(500, 7, false);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.pos[i] = Vec<2>{{3.0 * p.pos[i][0] - 1.5, 2.0 * p.pos[i][1] - 1.0}};
    p.h[i] = 0.02 + 1e-4 * static_cast<double>(i % 10);
  }
  return p;
}

std::vector<double> header_doubles(const std::string& path, const std::string& name) {
  h5::Handle f = h5::open_file_readonly(path);
  return h5::read_attr_doubles(h5::open_group(f, "Header", path), name, path);
}
}  // namespace

// yt's SWIFT frontend takes the domain as [0, BoxSize]^3: every particle and its kernel (2 h) must
// lie inside, around the central mass at PointMassPosition = BoxSize / 2.
TEST(Snapshot, CoordinatesLieInTheBoxAroundThePointMass) {
  const auto p = centred_particles();
  const std::string path = (temp_dir() / "layout.hdf5").string();
  write_snapshot(path, p, SnapshotMeta{});
  const std::vector<double> box = header_doubles(path, "BoxSize");
  const std::vector<double> centre = header_doubles(path, "PointMassPosition");
  ASSERT_EQ(box.size(), 3u);
  ASSERT_EQ(centre.size(), 3u);
  for (int d = 0; d < 3; ++d) {
    EXPECT_EQ(box[d], box[0]);
    EXPECT_EQ(centre[d], box[0] / 2);
  }
  h5::Handle f = h5::open_file_readonly(path);
  std::size_t rows, cols;
  const std::vector<double> x = h5::read_dataset_doubles(h5::open_group(f, "PartType0", path), "Coordinates", path, rows, cols);
  ASSERT_EQ(cols, 3u);
  std::map<std::uint64_t, std::size_t> where;
  for (std::size_t i = 0; i < p.size(); ++i) where[p.id[i]] = i;
  std::vector<std::uint64_t> ids(p.id);
  std::sort(ids.begin(), ids.end());
  for (std::size_t k = 0; k < rows; ++k) {
    const std::size_t i = where.at(ids[k]);
    for (int d = 0; d < 3; ++d) {
      const double xd = d < 2 ? p.pos[i][d] : 0.0;
      EXPECT_EQ(x[3 * k + static_cast<std::size_t>(d)], xd + centre[d]);
      EXPECT_GE(x[3 * k + static_cast<std::size_t>(d)] - 2 * p.h[i], 0.0);
      EXPECT_LE(x[3 * k + static_cast<std::size_t>(d)] + 2 * p.h[i], box[d]);
    }
  }
  // Short numbers: 4 significant bits, at most 1/8 above the extent.
  const double extent = 1.5 + 2 * 0.0209;  // the largest |x_c| + 2 h is below this
  EXPECT_LE(box[0], 2 * extent * 1.125);
  EXPECT_EQ(std::ldexp(box[0], -std::ilogb(box[0]) + 3), std::floor(std::ldexp(box[0], -std::ilogb(box[0]) + 3)));
}

// A debug dump of a run gone wrong: an infinite position leaves the box finite, so the other
// particles keep their Coordinates.
TEST(Snapshot, NonFinitePositionsLeaveTheBoxFinite) {
  auto p = centred_particles();
  p.pos[3] = Vec<2>{{0.0, 0.0}};
  p.pos[4] = Vec<2>{{0.0, 0.0}};
  const double box = snapshot_box_size(p);
  p.pos[3][0] = std::numeric_limits<double>::infinity();
  p.pos[4][1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(snapshot_box_size(p), box);  // the non-finite ones are left out
}

// What yt's SWIFT frontend reads: Code "SWIFT" (sphdisk's name in CodeName), Dimension 3, SWIFT's unit
// names, no periodic boundaries, no cosmology.
TEST(Snapshot, CarriesTheSwiftMetadata) {
  const auto p = centred_particles();
  SnapshotMeta meta;
  meta.units = UnitSystem::from_solar(1.0, 1.0);
  const std::string path = (temp_dir() / "swift.hdf5").string();
  write_snapshot(path, p, meta);
  h5::Handle f = h5::open_file_readonly(path);
  h5::Handle header = h5::open_group(f, "Header", path);
  EXPECT_EQ(h5::read_attr_string(header, "Code", path), "SWIFT");
  EXPECT_EQ(h5::read_attr_string(header, "CodeName", path), "sphdisk");
  EXPECT_EQ(h5::read_attr_double(header, "Dimension", path), 3.0);
  EXPECT_EQ(h5::read_attr_double(header, "SimulationDimension", path), 2.0);
  h5::Handle units = h5::open_group(f, "Units", path);
  EXPECT_EQ(h5::read_attr_double(units, "Unit length in cgs (U_L)", path), meta.units.length_cm);
  EXPECT_EQ(h5::read_attr_double(units, "UnitLength_in_cm", path), meta.units.length_cm);
  EXPECT_EQ(h5::read_attr_double(units, "Unit mass in cgs (U_M)", path), meta.units.mass_g);
  EXPECT_EQ(h5::read_attr_double(units, "Unit time in cgs (U_t)", path), meta.units.time_s);
  EXPECT_EQ(h5::read_attr_double(units, "Unit temperature in cgs (U_T)", path), 1.0);
  EXPECT_EQ(h5::read_attr_double(h5::open_group(f, "RuntimePars", path), "PeriodicBoundariesOn", path), 0.0);
  EXPECT_EQ(h5::read_attr_double(h5::open_group(f, "Policy", path), "cosmological integration", path), 0.0);
  EXPECT_TRUE(h5::exists(f, "HydroScheme"));
  EXPECT_TRUE(h5::exists(f, "SubgridScheme"));
}

// A file without PointMassPosition (written before it existed, or made by hand) holds positions
// relative to the central mass: they are read as stored. The fixture is a 400-particle ring
// snapshot of that layout.
TEST(Snapshot, FilesWithoutPointMassPositionAreReadAsCentred) {
  const std::string fixture = std::string(SPHDISK_SOURCE_DIR) + "/tests/fixtures/snapshot_origin_centred.hdf5";
  h5::Handle f = h5::open_file_readonly(fixture);
  ASSERT_FALSE(h5::has_attr(h5::open_group(f, "Header", fixture), "PointMassPosition"));
  std::size_t rows, cols;
  const std::vector<double> x = h5::read_dataset_doubles(h5::open_group(f, "PartType0", fixture), "Coordinates", fixture, rows, cols);
  SnapshotMeta meta;
  const auto q = read_snapshot<2>(fixture, nullptr, meta);
  ASSERT_EQ(q.size(), 400u);
  for (std::size_t k = 0; k < q.size(); ++k)
    for (int d = 0; d < 2; ++d) ASSERT_EQ(q.pos[k][d], x[3 * k + static_cast<std::size_t>(d)]);
}

TEST(Snapshot, MalformedPointMassPositionIsAUserError) {
  const std::string path = (temp_dir() / "bad_centre.hdf5").string();
  write_snapshot(path, centred_particles(), SnapshotMeta{});
  {
    h5::Handle f(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
    h5::Handle header = h5::open_group(f, "Header", path);
    ASSERT_GE(H5Adelete(header, "PointMassPosition"), 0);
    h5::write_attr(header, "PointMassPosition", std::vector<double>{1.0, 1.0});
  }
  SnapshotMeta meta;
  EXPECT_THROW(read_snapshot<2>(path, nullptr, meta), UserError);
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
