#include "solver/io/checkpoint.h"

#include <bit>
#include <cstring>
#include <iterator>
#include <limits>
#include <span>
#include <stdexcept>


#include "capsim/version.h"
#include "solver/io/atomic_file.h"
#include "solver/io/hdf5_support.h"

namespace capsim::io {
namespace {

constexpr const char* kFormat = "capsim-checkpoint";
// Strings inside the checksummed object headers: HDF5's global heap (variable-length strings) is not
// checksummed and a damaged one crashes the reader (found by the byte-flip sweep in the tests).
constexpr auto kFixed = h5::StringStorage::Fixed;

struct Column {
  const char* name;
  std::vector<double> diagnostics::TimeSeries::*member;
  bool optional = false;  // added later: a checkpoint without it reads as `absent`, hashed without it
  double absent = 0.0;
};
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr Column kColumns[] = {
    {"t", &diagnostics::TimeSeries::t},           {"D12", &diagnostics::TimeSeries::D12},
    {"L1", &diagnostics::TimeSeries::L1},         {"L2", &diagnostics::TimeSeries::L2},
    {"theta", &diagnostics::TimeSeries::theta},   {"tau_min", &diagnostics::TimeSeries::tau_min},
    {"volume", &diagnostics::TimeSeries::volume}, {"area", &diagnostics::TimeSeries::area},
    {"bending_energy", &diagnostics::TimeSeries::bending_energy, true},
    {"max_bending_moment", &diagnostics::TimeSeries::max_bending_moment, true},
    // The material axis; what a checkpoint from before it reads as: as in case_file.cc.
    {"axis_x1", &diagnostics::TimeSeries::axis_x1, true, kNaN},
    {"axis_x2", &diagnostics::TimeSeries::axis_x2, true, kNaN},
    {"axis_x3", &diagnostics::TimeSeries::axis_x3, true, kNaN},
    {"axis_tilt", &diagnostics::TimeSeries::axis_tilt, true, 0.0},
    {"axis_azimuth", &diagnostics::TimeSeries::axis_azimuth, true, kNaN},
    // The 3D ellipsoid of inertia and the spin; a checkpoint from before them reads them as NaN (as case_file.cc).
    {"La", &diagnostics::TimeSeries::La, true, kNaN},
    {"Lb", &diagnostics::TimeSeries::Lb, true, kNaN},
    {"Lc", &diagnostics::TimeSeries::Lc, true, kNaN},
    {"ea_x1", &diagnostics::TimeSeries::ea_x1, true, kNaN},
    {"ea_x2", &diagnostics::TimeSeries::ea_x2, true, kNaN},
    {"ea_x3", &diagnostics::TimeSeries::ea_x3, true, kNaN},
    {"eb_x1", &diagnostics::TimeSeries::eb_x1, true, kNaN},
    {"eb_x2", &diagnostics::TimeSeries::eb_x2, true, kNaN},
    {"eb_x3", &diagnostics::TimeSeries::eb_x3, true, kNaN},
    {"ec_x1", &diagnostics::TimeSeries::ec_x1, true, kNaN},
    {"ec_x2", &diagnostics::TimeSeries::ec_x2, true, kNaN},
    {"ec_x3", &diagnostics::TimeSeries::ec_x3, true, kNaN},
    {"spin", &diagnostics::TimeSeries::spin, true, kNaN},
};
static_assert(std::size(kColumns) <= 64, "the checksum's `absent` mask has one bit per column");

std::string ts(const char* col) { return std::string("timeseries/") + col; }

// FNV-1a, 64 bit: simple, no dependency, and any flipped byte changes it.
class Fnv1a {
 public:
  void bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ b[i]) * 0x100000001b3ULL;
  }
  template <class T>
  void value(const T& v) {
    bytes(&v, sizeof v);
  }
  void string(const std::string& s) {
    value(static_cast<std::uint64_t>(s.size()));
    bytes(s.data(), s.size());
  }
  [[nodiscard]] std::uint64_t get() const { return h_; }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ULL;
};

// absent: the optional columns a checkpoint written before them lacks (each was added later, so each has its own
// bit: a checkpoint with the bending columns but not the axis ones was hashed over the former only). Columns are
// indexed in kColumns order; absent = 0 is the checksum of a checkpoint with every column.
std::uint64_t checksum(const Checkpoint& c, std::uint64_t absent = 0) {
  Fnv1a h;
  h.value(static_cast<std::uint64_t>(c.positions.cols()));
  h.bytes(c.positions.data(), sizeof(double) * static_cast<std::size_t>(c.positions.size()));
  h.value(c.time);
  h.value(c.step);
  h.value(c.dt);
  h.value(static_cast<std::uint64_t>(c.series.size()));
  for (std::size_t k = 0; k < std::size(kColumns); ++k) {
    const auto& col = kColumns[k];
    if (col.optional && (absent >> k & 1U)) continue;
    const auto& v = c.series.*col.member;
    h.bytes(v.data(), sizeof(double) * v.size());
  }
  h.bytes(c.series.P.data(), sizeof(double) * 3 * c.series.P.size());
  for (const auto& [k, v] : c.scalars) h.string(k), h.value(v);
  for (const auto& [k, v] : c.strings) h.string(k), h.string(v);
  return h.get();
}

void write_contents(const std::filesystem::path& tmp, const std::filesystem::path& file, const Checkpoint& c) {
  h5::Handle fapl = h5::checked(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, file, "cannot create a property list");
  // The 1.10 file format checksums all metadata, so damage to the file structure is detected too.
  h5::check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V110, H5F_LIBVER_LATEST), file, "cannot set the format");
  h5::Handle f = h5::checked(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), H5Fclose, file,
                             "cannot create temporary checkpoint " + tmp.string());
  const hid_t id = f.get();
  h5::write_attribute(id, Attribute("format", kFormat), file, kFixed);
  h5::write_attribute(id, Attribute("format_version", static_cast<long long>(kCheckpointFormatVersion)), file);
  h5::write_attribute(id, Attribute("code_version", kGitCommit), file, kFixed);
  h5::write_attribute(id, Attribute("time", c.time), file);
  h5::write_attribute(id, Attribute("step", static_cast<long long>(c.step)), file);
  h5::write_attribute(id, Attribute("dt", c.dt), file);
  h5::write_attribute(id, Attribute("num_nodes", static_cast<long long>(c.positions.cols())), file);
  h5::write_attribute(id, Attribute("num_records", static_cast<long long>(c.series.size())), file);
  h5::write_attribute(id, Attribute("checksum", static_cast<long long>(std::bit_cast<std::int64_t>(checksum(c)))),
                      file);
  h5::write_dataset(id, "positions", {static_cast<hsize_t>(c.positions.cols()), 3}, c.positions.data(), file);
  const auto n = static_cast<hsize_t>(c.series.size());
  for (const auto& col : kColumns) h5::write_dataset(id, ts(col.name), {n}, (c.series.*col.member).data(), file);
  h5::write_dataset(id, ts("P"), {n, 3}, n ? c.series.P.front().data() : nullptr, file);
  for (const char* g : {"scalars", "strings"}) {
    h5::Handle grp = h5::checked(H5Gcreate2(id, g, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, file,
                                 std::string("cannot create group ") + g);
    if (std::string(g) == "scalars")
      for (const auto& [k, v] : c.scalars) h5::write_attribute(grp.get(), Attribute(k, v), file);
    else
      for (const auto& [k, v] : c.strings) h5::write_attribute(grp.get(), Attribute(k, v), file, kFixed);
  }
  f.close(file, "cannot close temporary checkpoint " + tmp.string());
}

}  // namespace

void write_checkpoint(const std::filesystem::path& file, const Checkpoint& c) {
  h5::silence_errors();
  if (!c.series.consistent()) throw std::invalid_argument("write_checkpoint: inconsistent time series");
  for (const auto& [k, v] : c.scalars)
    if (k.empty()) throw std::invalid_argument("write_checkpoint: empty scalar key");
  for (const auto& [k, v] : c.strings)
    if (k.empty() || v.find('\0') != std::string::npos)
      throw std::invalid_argument("write_checkpoint: empty string key or NUL in string '" + k + "'");
  replace_file_atomically(file, [&](const std::filesystem::path& tmp) { write_contents(tmp, file, c); });
}

Checkpoint read_checkpoint(const std::filesystem::path& file) {
  h5::silence_errors();
  if (!std::filesystem::exists(file)) throw IoError(file, "checkpoint not found");
  if (H5Fis_hdf5(file.c_str()) <= 0) {
    H5Eclear2(H5E_DEFAULT);
    throw IoError(file, "checkpoint is not an HDF5 file (corrupt or truncated)");
  }
  h5::Handle f = h5::checked(H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, file,
                             "cannot open checkpoint (corrupt or truncated?)");
  const hid_t id = f.get();
  const auto fmt = h5::read_attribute(id, "format", file);
  if (!fmt || !std::holds_alternative<std::string>(fmt->value) || std::get<std::string>(fmt->value) != kFormat)
    throw IoError(file, "not a capsim checkpoint (attribute format != \"capsim-checkpoint\")");
  const auto version = h5::require_int(id, "format_version", file);
  if (version != kCheckpointFormatVersion)
    throw IoError(file, "unsupported checkpoint format_version " + std::to_string(version) + " (this build reads " +
                            std::to_string(kCheckpointFormatVersion) + ")");
  Checkpoint c;
  c.time = h5::require_double(id, "time", file);
  c.step = h5::require_int(id, "step", file);
  c.dt = h5::require_double(id, "dt", file);
  const auto num_nodes = h5::require_int(id, "num_nodes", file);
  const auto num_records = h5::require_int(id, "num_records", file);
  const auto stored_sum = std::bit_cast<std::uint64_t>(h5::require_int(id, "checksum", file));
  if (num_nodes < 0 || num_records < 0) throw IoError(file, "negative sizes in checkpoint");

  const auto pd = h5::dataset_dims(id, "positions", file);
  if (pd.size() != 2 || pd[1] != 3 || static_cast<std::int64_t>(pd[0]) != num_nodes)
    throw IoError(file, "dataset positions is not num_nodes × 3 (" + std::to_string(num_nodes) + " × 3)");
  c.positions.resize(3, num_nodes);
  h5::read_dataset(id, "positions", 3 * static_cast<std::size_t>(num_nodes), c.positions.data(), file);

  const auto n = static_cast<std::size_t>(num_records);
  std::uint64_t absent = 0;
  for (std::size_t k = 0; k < std::size(kColumns); ++k) {
    const auto& col = kColumns[k];
    if (col.optional && !h5::exists(id, ts(col.name))) {
      (c.series.*col.member).assign(n, col.absent);
      absent |= std::uint64_t{1} << k;
      continue;
    }
    const auto d = h5::dataset_dims(id, ts(col.name), file);
    if (d.size() != 1 || d[0] != n)
      throw IoError(file, "dataset " + ts(col.name) + " does not have num_records = " + std::to_string(n) + " rows");
    auto& v = c.series.*col.member;
    v.resize(n);
    h5::read_dataset(id, ts(col.name), n, v.data(), file);
  }
  const auto d = h5::dataset_dims(id, ts("P"), file);
  if (d.size() != 2 || d[0] != n || d[1] != 3)
    throw IoError(file, "dataset timeseries/P is not num_records × 3");
  c.series.P.resize(n);
  h5::read_dataset(id, ts("P"), 3 * n, n ? c.series.P.front().data() : nullptr, file);

  for (const char* g : {"scalars", "strings"}) {
    if (!h5::exists(id, g)) throw IoError(file, std::string("missing group ") + g);
    h5::Handle grp = h5::checked(H5Gopen2(id, g, H5P_DEFAULT), H5Gclose, file, std::string("cannot open group ") + g);
    for (auto& a : h5::read_attributes(grp.get(), file)) {
      if (std::string(g) == "scalars") {
        if (!std::holds_alternative<double>(a.value)) throw IoError(file, "scalar " + a.key + " is not a number");
        c.scalars.emplace(a.key, std::get<double>(a.value));
      } else {
        if (!std::holds_alternative<std::string>(a.value)) throw IoError(file, "string " + a.key + " is not a string");
        c.strings.emplace(a.key, std::get<std::string>(a.value));
      }
    }
  }
  f.close(file, "cannot close checkpoint");
  if (checksum(c, absent) != stored_sum) throw IoError(file, "checkpoint is corrupt (checksum mismatch)");
  return c;
}

bool bitwise_equal(const Checkpoint& a, const Checkpoint& b) {
  auto same = [](const void* p, const void* q, std::size_t n) { return n == 0 || std::memcmp(p, q, n) == 0; };
  if (a.positions.cols() != b.positions.cols() || a.series.size() != b.series.size()) return false;
  if (!same(a.positions.data(), b.positions.data(), sizeof(double) * a.positions.size())) return false;
  if (!same(&a.time, &b.time, sizeof a.time) || a.step != b.step || !same(&a.dt, &b.dt, sizeof a.dt)) return false;
  for (const auto& col : kColumns)
    if (!same((a.series.*col.member).data(), (b.series.*col.member).data(), sizeof(double) * a.series.size()))
      return false;
  if (!same(a.series.P.data(), b.series.P.data(), sizeof(double) * 3 * a.series.size())) return false;
  if (a.strings != b.strings || a.scalars.size() != b.scalars.size()) return false;
  for (auto i = a.scalars.begin(), j = b.scalars.begin(); i != a.scalars.end(); ++i, ++j)
    if (i->first != j->first || !same(&i->second, &j->second, sizeof(double))) return false;
  return true;
}

}  // namespace capsim::io
