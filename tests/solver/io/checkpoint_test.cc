// Checkpoints: bitwise round trip, atomic replacement, and every kind of damaged file → IoError.
#include "solver/io/checkpoint.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>

#include <gtest/gtest.h>
#include <hdf5.h>

#include "solver/io/io_error.h"

namespace capsim::io {
namespace {

std::filesystem::path scratch(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(CAPSIM_TEST_TMP) / "io_checkpoint";
  std::filesystem::create_directories(dir);
  return dir / name;
}

Checkpoint sample_checkpoint(int nodes = 642, int records = 777) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-2, 2);
  Checkpoint c;
  c.positions.resize(3, nodes);
  for (int i = 0; i < c.positions.size(); ++i) c.positions.data()[i] = u(rng);
  // Values a lossy path would alter: signed zero, a denormal, extremes, a NaN with a payload.
  c.positions(0, 0) = -0.0;
  c.positions(1, 0) = 4.9e-324;
  c.positions(2, 0) = std::numeric_limits<double>::max();
  c.positions(0, 1) = std::bit_cast<double>(0x7ff8000000012345ULL);
  c.time = 12.345678901234567;
  c.step = 123456789012LL;
  c.dt = 1.0 / 3.0;
  for (int i = 0; i < records; ++i)
    c.series.push_back(
        {0.01 * i, u(rng), u(rng), u(rng), u(rng), u(rng), u(rng), u(rng), {u(rng), u(rng), u(rng)}, u(rng), u(rng),
         {u(rng), u(rng), u(rng)}, u(rng), u(rng)});
  c.scalars = {{"p_node", 17}, {"initial volume", 4.18879020478639}, {"a/b", 2.0}, {"tiny", 1e-300}};
  c.strings = {{"case_id", "Ca=0.3 r=2 skalak L3"}, {"unicode", "τmin ≥ 0"}};
  return c;
}

std::vector<char> read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::filesystem::path& p, const std::vector<char>& b, std::size_t n) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(b.data(), static_cast<std::streamsize>(n));
}

void expect_io_error_naming(const std::filesystem::path& p, const std::string& fragment = "") {
  try {
    (void)read_checkpoint(p);
    ADD_FAILURE() << "no exception for " << p;
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
    if (!fragment.empty()) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  }
}

TEST(Checkpoint, RoundTripIsBitwise) {
  const auto file = scratch("ck.h5");
  const Checkpoint c = sample_checkpoint();
  write_checkpoint(file, c);
  const Checkpoint r = read_checkpoint(file);
  EXPECT_TRUE(bitwise_equal(c, r));
  EXPECT_EQ(std::bit_cast<std::uint64_t>(r.positions(0, 1)), 0x7ff8000000012345ULL);
  EXPECT_TRUE(std::signbit(r.positions(0, 0)));
  // No temporary file of this checkpoint left behind. Only "ck.h5.tmp-*" counts: the other tests of
  // this suite write their own checkpoints into the same directory, in parallel under ctest -j.
  const std::string own_tmp = file.filename().string() + ".tmp-";
  for (const auto& e : std::filesystem::directory_iterator(file.parent_path()))
    EXPECT_NE(e.path().filename().string().rfind(own_tmp, 0), 0u) << e.path();
}

TEST(Checkpoint, EmptySeriesAndMapsRoundTrip) {
  const auto file = scratch("empty.h5");
  Checkpoint c;
  c.positions = Eigen::Matrix3Xd::Random(3, 12);
  write_checkpoint(file, c);
  EXPECT_TRUE(bitwise_equal(c, read_checkpoint(file)));
}

TEST(Checkpoint, RewriteReplacesThePreviousOne) {
  const auto file = scratch("replace.h5");
  Checkpoint a = sample_checkpoint(100, 10), b = sample_checkpoint(200, 20);
  b.step = 7;
  write_checkpoint(file, a);
  write_checkpoint(file, b);
  EXPECT_TRUE(bitwise_equal(b, read_checkpoint(file)));
  EXPECT_FALSE(bitwise_equal(a, b));
}

TEST(Checkpoint, FailedWriteLeavesThePreviousFile) {
  const auto file = scratch("keep.h5");
  const Checkpoint a = sample_checkpoint(50, 5);
  write_checkpoint(file, a);
  Checkpoint bad = a;
  bad.series.t.pop_back();  // inconsistent: rejected before anything is written
  EXPECT_THROW(write_checkpoint(file, bad), std::invalid_argument);
  EXPECT_THROW(write_checkpoint(scratch("no_dir") / "ck.h5", a), IoError);
  EXPECT_TRUE(bitwise_equal(a, read_checkpoint(file)));
}

TEST(Checkpoint, TruncatedFilesThrowNamingTheFile) {
  const auto file = scratch("whole.h5");
  write_checkpoint(file, sample_checkpoint());
  const auto bytes = read_bytes(file);
  const auto cut = scratch("truncated.h5");
  for (std::size_t n : {std::size_t{0}, std::size_t{7}, std::size_t{100}, bytes.size() / 3, bytes.size() / 2,
                        bytes.size() - 1000, bytes.size() - 1}) {
    write_bytes(cut, bytes, n);
    SCOPED_TRACE(n);
    expect_io_error_naming(cut);
  }
}

TEST(Checkpoint, FlippedDataByteFailsTheChecksum) {
  const auto file = scratch("flip.h5");
  write_checkpoint(file, sample_checkpoint());
  // Locate the raw data of `positions` (contiguous) and damage one byte in the middle of it.
  hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  hid_t d = H5Dopen2(f, "positions", H5P_DEFAULT);
  const haddr_t offset = H5Dget_offset(d);
  H5Dclose(d);
  H5Fclose(f);
  ASSERT_NE(offset, HADDR_UNDEF);
  auto bytes = read_bytes(file);
  bytes[offset + 1000] ^= 0x10;
  write_bytes(file, bytes, bytes.size());
  expect_io_error_naming(file, "checksum");
}

TEST(Checkpoint, AnyFlippedByteThrowsOrReadsTheSameData) {
  // Sweep single-byte damage over the whole file: the reader must never crash or return other data.
  const auto file = scratch("sweep.h5");
  const Checkpoint c = sample_checkpoint(60, 40);
  write_checkpoint(file, c);
  const auto bytes = read_bytes(file);
  const auto damaged = scratch("sweep_damaged.h5");
  int thrown = 0, same = 0;
  for (std::size_t i = 0; i < bytes.size(); i += 7) {
    auto b = bytes;
    b[i] = static_cast<char>(b[i] ^ 0xA5);
    write_bytes(damaged, b, b.size());
    try {
      const Checkpoint r = read_checkpoint(damaged);
      EXPECT_TRUE(bitwise_equal(c, r)) << "byte " << i << " changed the data silently";
      ++same;
    } catch (const IoError&) {
      ++thrown;
    }
  }
  std::printf("%zu bytes, %d damaged copies rejected, %d read back unchanged (unused bytes)\n", bytes.size(),
              thrown, same);
  EXPECT_GT(thrown, 0);
}

TEST(Checkpoint, MissingDatasetOrWrongVersionIsRejected) {
  const auto file = scratch("edit.h5");
  write_checkpoint(file, sample_checkpoint(30, 30));
  {
    hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(H5Ldelete(f, "timeseries/L1", H5P_DEFAULT), 0);
    H5Fclose(f);
  }
  expect_io_error_naming(file, "timeseries/L1");

  write_checkpoint(file, sample_checkpoint(30, 30));
  {
    hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t a = H5Aopen(f, "format_version", H5P_DEFAULT);
    const std::int64_t v = 99;
    H5Awrite(a, H5T_NATIVE_INT64, &v);
    H5Aclose(a);
    H5Fclose(f);
  }
  expect_io_error_naming(file, "format_version 99");

  write_checkpoint(file, sample_checkpoint(30, 30));
  {
    hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t a = H5Aopen(f, "num_nodes", H5P_DEFAULT);
    const std::int64_t v = 31;
    H5Awrite(a, H5T_NATIVE_INT64, &v);
    H5Aclose(a);
    H5Fclose(f);
  }
  expect_io_error_naming(file, "positions");
}

TEST(Checkpoint, MissingOrForeignFilesAreRejected) {
  expect_io_error_naming(scratch("does_not_exist.h5"), "not found");
  const auto text = scratch("garbage.h5");
  std::ofstream(text) << "this is not HDF5";
  expect_io_error_naming(text, "not an HDF5 file");
  // A valid HDF5 file of another kind.
  const auto other = scratch("other.h5");
  hid_t f = H5Fcreate(other.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  H5Fclose(f);
  expect_io_error_naming(other, "not a capsim checkpoint");
}

// A checkpoint written before the bending columns existed (committed fixture, code of 2b1b812, see
// case_file_test) reads — checksum verified without those columns — with zero bending columns; a flipped
// byte in it is still caught.
TEST(Checkpoint, CheckpointFromBeforeTheBendingColumnsReads) {
  const auto src = std::filesystem::path(CAPSIM_SOURCE_DIR) / "tests/solver/io/data/pre_bending_checkpoint.h5";
  const Checkpoint c = read_checkpoint(src);
  ASSERT_GT(c.series.size(), 0u);
  EXPECT_TRUE(c.series.consistent());
  for (std::size_t i = 0; i < c.series.size(); ++i) EXPECT_EQ(c.series.bending_energy[i], 0.0);
  // Nor the material axis: an in-plane case (tilt exactly 0), its direction unrecorded (NaN).
  for (std::size_t i = 0; i < c.series.size(); ++i) {
    EXPECT_EQ(c.series.axis_tilt[i], 0.0);
    EXPECT_TRUE(std::isnan(c.series.axis_azimuth[i]));
    EXPECT_TRUE(std::isnan(c.series.axis_x1[i]));
    EXPECT_TRUE(std::isnan(c.series.La[i]) && std::isnan(c.series.spin[i]));  // nor the 3D ellipsoid and spin
  }
  EXPECT_EQ(c.step, 5);
  // Written again by this code, it has the columns and reads back bitwise.
  const auto file = scratch("pre_bending_rewritten.h5");
  write_checkpoint(file, c);
  EXPECT_TRUE(bitwise_equal(c, read_checkpoint(file)));
}

// A checkpoint of the build before the 3D ellipsoid and the spin (committed fixture, code of 9bf4090, a tilted case:
// see tests/solver/driver/orientation_diagnostics_test.cc, which resumes it) reads — checksum verified without the
// new columns only, the axis columns present — with the new columns NaN and no spin among its scalars.
TEST(Checkpoint, CheckpointFromBeforeTheSpinReads) {
  const auto src = std::filesystem::path(CAPSIM_SOURCE_DIR) / "tests/solver/io/data/pre_spin_checkpoint.h5";
  const Checkpoint c = read_checkpoint(src);
  ASSERT_EQ(c.series.size(), 5u);
  EXPECT_TRUE(c.series.consistent());
  for (std::size_t i = 0; i < c.series.size(); ++i) {
    EXPECT_NEAR(c.series.axis_tilt[i], 30.0, 1.0) << "the axis columns were there";
    EXPECT_TRUE(std::isfinite(c.series.axis_x1[i]));
    EXPECT_TRUE(std::isnan(c.series.La[i]) && std::isnan(c.series.eb_x2[i]) && std::isnan(c.series.spin[i]));
  }
  EXPECT_EQ(c.scalars.count("spin"), 0u);
  EXPECT_EQ(c.scalars.count("p_node"), 1u);
  const auto file = scratch("pre_spin_rewritten.h5");
  write_checkpoint(file, c);
  EXPECT_TRUE(bitwise_equal(c, read_checkpoint(file)));
  // A flipped byte in the positions is still caught by the checksum taken without the new columns.
  hid_t f = H5Fopen(src.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  hid_t d = H5Dopen2(f, "positions", H5P_DEFAULT);
  const haddr_t offset = H5Dget_offset(d);
  H5Dclose(d);
  H5Fclose(f);
  ASSERT_NE(offset, HADDR_UNDEF);
  auto bytes = read_bytes(src);
  bytes[offset + 100] ^= 0x10;
  const auto damaged = scratch("pre_spin_damaged.h5");
  write_bytes(damaged, bytes, bytes.size());
  expect_io_error_naming(damaged, "checksum");
}

}  // namespace
}  // namespace capsim::io
