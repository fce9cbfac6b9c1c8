#include "solver/io/case_file.h"

#include <algorithm>
#include <cctype>
#include <limits>
#include <cstdio>
#include <stdexcept>

#include "capsim/version.h"
#include "solver/io/hdf5_support.h"
#include "solver/io/atomic_file.h"
#include "solver/io/xdmf.h"

namespace capsim::io {
namespace {

constexpr const char* kFormat = "capsim-case";
constexpr const char* kReserved[] = {"format", "format_version", "code_version", "capsim_version"};

// The 1-D columns of the time series, their units and descriptions (stored as the `units` and `description`
// attributes of each dataset) and accessors. solver/README.md §5 documents them at length.
struct Column {
  const char* name;
  const char* units;
  const char* description;
  std::vector<double> diagnostics::TimeSeries::*member;
  bool optional = false;  // added later: a file without it reads as `absent`
  double absent = 0.0;    // what an optional column reads as in a file from before it
};
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr Column kColumns[] = {
    {"t", "1/shear_rate", "time", &diagnostics::TimeSeries::t},
    {"D12", "1", "Taylor parameter (L1 - L2)/(L1 + L2) of the ellipsoid of inertia in the shear plane",
     &diagnostics::TimeSeries::D12},
    {"L1", "l", "longer semi-axis of the ellipsoid of inertia in the shear plane (x1, x2)", &diagnostics::TimeSeries::L1},
    {"L2", "l", "shorter semi-axis of the ellipsoid of inertia in the shear plane", &diagnostics::TimeSeries::L2},
    {"theta", "rad", "inclination of L1 to x1, counter-clockwise, in (-pi/2, pi/2]", &diagnostics::TimeSeries::theta},
    {"tau_min", "Gs", "smallest principal tension over the membrane", &diagnostics::TimeSeries::tau_min},
    {"volume", "l^3", "enclosed volume", &diagnostics::TimeSeries::volume},
    {"area", "l^2", "membrane area", &diagnostics::TimeSeries::area},
    {"bending_energy", "Gs*l^2", "bending energy W_b (0 without bending stiffness)",
     &diagnostics::TimeSeries::bending_energy, true},
    {"max_bending_moment", "Gs*l", "largest bending moment kappa_b |c - c0| (0 without bending stiffness)",
     &diagnostics::TimeSeries::max_bending_moment, true},
    // The material axis (solver/README.md, Orientation). A file from before it holds an in-plane case, whose axis
    // stayed exactly in the plane (the mirror kept bitwise): tilt 0; its direction was not recorded: NaN.
    {"axis_x1", "1", "material axis (unit, from the node that started at the -x1 pole to the +x1 one), x1 component",
     &diagnostics::TimeSeries::axis_x1, true, kNaN},
    {"axis_x2", "1", "material axis, x2 component", &diagnostics::TimeSeries::axis_x2, true, kNaN},
    {"axis_x3", "1", "material axis, x3 component", &diagnostics::TimeSeries::axis_x3, true, kNaN},
    {"axis_tilt", "deg", "angle of the material axis out of the shear plane, [0, 90]", &diagnostics::TimeSeries::axis_tilt,
     true, 0.0},
    {"axis_azimuth", "deg", "angle of the material axis's projection on the shear plane from x1 toward x2, (-90, 90]",
     &diagnostics::TimeSeries::axis_azimuth, true, kNaN},
    // The 3D ellipsoid of inertia and the spin (solver/README.md §5). A file from before them did not record them:
    // NaN (an in-plane case's La..Lc are not L1, L2, L3 in some order known without the shape).
    {"La", "l", "largest semi-axis of the 3D ellipsoid of inertia, sqrt(5 mu_a / V)", &diagnostics::TimeSeries::La,
     true, kNaN},
    {"Lb", "l", "middle semi-axis of the 3D ellipsoid of inertia", &diagnostics::TimeSeries::Lb, true, kNaN},
    {"Lc", "l", "smallest semi-axis of the 3D ellipsoid of inertia", &diagnostics::TimeSeries::Lc, true, kNaN},
    {"ea_x1", "1", "unit direction of La, x1 component (sign: x1 component positive, else x2, else x3)",
     &diagnostics::TimeSeries::ea_x1, true, kNaN},
    {"ea_x2", "1", "unit direction of La, x2 component", &diagnostics::TimeSeries::ea_x2, true, kNaN},
    {"ea_x3", "1", "unit direction of La, x3 component", &diagnostics::TimeSeries::ea_x3, true, kNaN},
    {"eb_x1", "1", "unit direction of Lb, x1 component", &diagnostics::TimeSeries::eb_x1, true, kNaN},
    {"eb_x2", "1", "unit direction of Lb, x2 component", &diagnostics::TimeSeries::eb_x2, true, kNaN},
    {"eb_x3", "1", "unit direction of Lb, x3 component", &diagnostics::TimeSeries::eb_x3, true, kNaN},
    {"ec_x1", "1", "unit direction of Lc, x1 component", &diagnostics::TimeSeries::ec_x1, true, kNaN},
    {"ec_x2", "1", "unit direction of Lc, x2 component", &diagnostics::TimeSeries::ec_x2, true, kNaN},
    {"ec_x3", "1", "unit direction of Lc, x3 component", &diagnostics::TimeSeries::ec_x3, true, kNaN},
    {"spin", "rad",
     "membrane rotation about the material axis since the start (the equator node's turn, the axis's own turn "
     "transported out), counter-clockwise about the axis, unwrapped",
     &diagnostics::TimeSeries::spin, true, kNaN},
};

std::string ts(const char* col) { return std::string("timeseries/") + col; }

bool valid_field_name(const std::string& n) {
  return !n.empty() && n != "positions" && std::all_of(n.begin(), n.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  });
}

// Names of the links of a group in increasing name order.
std::vector<std::string> link_names(hid_t group, const std::filesystem::path& file) {
  std::vector<std::string> names;
  auto cb = [](hid_t, const char* name, const H5L_info_t*, void* data) -> herr_t {
    static_cast<std::vector<std::string>*>(data)->emplace_back(name);
    return 0;
  };
  hsize_t idx = 0;
  h5::check(H5Literate(group, H5_INDEX_NAME, H5_ITER_INC, &idx, cb, &names), file, "cannot list a group");
  return names;
}

h5::Handle open_file_checked(const std::filesystem::path& file, unsigned flags) {
  if (!std::filesystem::exists(file)) throw IoError(file, "no such file");
  const htri_t is = H5Fis_hdf5(file.c_str());
  if (is <= 0) {
    H5Eclear2(H5E_DEFAULT);
    throw IoError(file, "not an HDF5 file (corrupt or truncated?)");
  }
  return h5::checked(H5Fopen(file.c_str(), flags, H5P_DEFAULT), H5Fclose, file, "cannot open");
}

void check_case_format(hid_t f, const std::filesystem::path& file) {
  const auto fmt = h5::read_attribute(f, "format", file);
  if (!fmt || !std::holds_alternative<std::string>(fmt->value) || std::get<std::string>(fmt->value) != kFormat)
    throw IoError(file, "not a capsim case file (attribute format != \"capsim-case\")");
  const auto v = h5::require_int(f, "format_version", file);
  if (v != kCaseFormatVersion)
    throw IoError(file, "unsupported case file format_version " + std::to_string(v) + " (this build reads " +
                            std::to_string(kCaseFormatVersion) + ")");
}

}  // namespace

struct CaseWriter::Impl {
  std::filesystem::path file;
  CaseFileOptions options;
  h5::Handle f;
  diagnostics::TimeSeries pending;
  std::size_t written = 0;
  long long next_snapshot = 0;
  long long num_elements = -1;  // of the mesh at the first snapshot

  void create_layout(const std::vector<Attribute>& parameters) {
    for (const auto& p : parameters)
      for (const char* r : kReserved)
        if (p.key == r) throw std::invalid_argument("case file parameter name '" + p.key + "' is reserved");
    h5::write_attribute(f.get(), Attribute("format", kFormat), file);
    h5::write_attribute(f.get(), Attribute("format_version", static_cast<long long>(kCaseFormatVersion)), file);
    h5::write_attribute(f.get(), Attribute("code_version", kGitCommit), file);
    h5::write_attribute(f.get(), Attribute("capsim_version", kVersion), file);
    for (const auto& p : parameters) h5::write_attribute(f.get(), p, file);
    for (const auto& c : kColumns) create_column(c);
    h5::create_extendible(f.get(), ts("P"), 3, options.chunk_rows, file);
    h5::Handle g = h5::checked(H5Gcreate2(f.get(), "snapshots", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
                               file, "cannot create group snapshots");
  }

  void create_column(const Column& c) {
    h5::create_extendible(f.get(), ts(c.name), 0, options.chunk_rows, file);
    h5::Handle d = h5::checked(H5Dopen2(f.get(), ts(c.name).c_str(), H5P_DEFAULT), H5Dclose, file, "open");
    h5::write_attribute(d.get(), Attribute("units", c.units), file);
    h5::write_attribute(d.get(), Attribute("description", c.description), file);
  }

  void write_pending() {
    const std::size_t n = pending.size();
    if (n == 0) return;
    for (const auto& c : kColumns) h5::append_rows(f.get(), ts(c.name), 0, n, (pending.*c.member).data(), file);
    h5::append_rows(f.get(), ts("P"), 3, n, pending.P.front().data(), file);
    written += n;
    pending.truncate(0);
  }

  void rewrite_xdmf() {
    h5::Handle g = h5::checked(H5Gopen2(f.get(), "snapshots", H5P_DEFAULT), H5Gclose, file, "cannot open snapshots");
    std::vector<XdmfSnapshot> snaps;
    for (const auto& name : link_names(g.get(), file)) {
      XdmfSnapshot s;
      s.group = "/snapshots/" + name;
      h5::Handle sg = h5::checked(H5Gopen2(g.get(), name.c_str(), H5P_DEFAULT), H5Gclose, file, "open " + s.group);
      s.t = h5::require_double(sg.get(), "t", file);
      s.num_nodes = static_cast<long long>(h5::dataset_dims(sg.get(), "positions", file)[0]);
      for (const auto& field : link_names(sg.get(), file)) {
        if (field == "positions") continue;
        const auto dims = h5::dataset_dims(sg.get(), field, file);
        s.fields.emplace_back(field, dims.size() == 2 ? static_cast<int>(dims[1]) : 1);
      }
      snaps.push_back(std::move(s));
    }
    XdmfTopologyRef topo;
    const bool p2 = options.topology == XdmfTopology::Triangle6;
    topo.dataset = p2 ? "/mesh/connectivity_p2" : "/mesh/connectivity_linear";
    topo.type = p2 ? "Triangle_6" : "Triangle";
    topo.nodes_per_element = p2 ? 6 : 3;
    topo.num_elements = (p2 ? 1 : 4) * num_elements;
    write_text_atomically(xdmf_path(), xdmf_document(file.filename().string(), topo, snaps));
  }

  [[nodiscard]] std::filesystem::path xdmf_path() const {
    std::filesystem::path x = file;
    x.replace_extension(".xmf");
    return x;
  }
};

CaseWriter::CaseWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

CaseWriter::CaseWriter(const std::filesystem::path& file, const std::vector<Attribute>& parameters,
                       const CaseFileOptions& options)
    : impl_(std::make_unique<Impl>()) {
  h5::silence_errors();
  impl_->file = file;
  impl_->options = options;
  impl_->options.buffer_rows = std::max<std::size_t>(options.buffer_rows, 1);
  impl_->options.chunk_rows = std::max<std::size_t>(options.chunk_rows, 1);
  impl_->f = h5::checked(H5Fcreate(file.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose, file,
                         "cannot create the case file");
  impl_->create_layout(parameters);
}

CaseWriter CaseWriter::resume(const std::filesystem::path& file, const std::vector<Attribute>& parameters,
                              const diagnostics::TimeSeries& series, const CaseFileOptions& options) {
  h5::silence_errors();
  if (!std::filesystem::exists(file)) {
    CaseWriter w(file, parameters, options);
    w.append(series);
    return w;
  }
  auto impl = std::make_unique<Impl>();
  impl->file = file;
  impl->options = options;
  impl->options.buffer_rows = std::max<std::size_t>(options.buffer_rows, 1);
  impl->f = open_file_checked(file, H5F_ACC_RDWR);
  check_case_format(impl->f.get(), file);
  for (const auto& p : parameters)
    for (const char* r : kReserved)
      if (p.key == r) throw std::invalid_argument("case file parameter name '" + p.key + "' is reserved");
  for (const auto& p : parameters) h5::write_attribute(impl->f.get(), p, file);
  // Replace the series by the checkpoint's: shrink to 0 and append it again (the series is small).
  impl->options.chunk_rows = std::max<std::size_t>(options.chunk_rows, 1);
  for (const auto& c : kColumns) {
    if (c.optional && !h5::exists(impl->f.get(), ts(c.name))) {
      impl->create_column(c);  // a file from before it
    } else {
      // A file from before the descriptions: its columns get theirs (the file then reads as a new one).
      h5::Handle d = h5::checked(H5Dopen2(impl->f.get(), ts(c.name).c_str(), H5P_DEFAULT), H5Dclose, file, "open");
      if (!h5::read_attribute(d.get(), "description", file))
        h5::write_attribute(d.get(), Attribute("description", c.description), file);
    }
    h5::set_rows(impl->f.get(), ts(c.name), 0, 0, file);
  }
  h5::set_rows(impl->f.get(), ts("P"), 3, 0, file);
  // Drop snapshots taken after the checkpoint: the restarted run will write them again.
  const double t_last = series.empty() ? -std::numeric_limits<double>::infinity() : series.t.back();
  {
    h5::Handle g = h5::checked(H5Gopen2(impl->f.get(), "snapshots", H5P_DEFAULT), H5Gclose, file, "open snapshots");
    for (const auto& name : link_names(g.get(), file)) {
      h5::Handle sg = h5::checked(H5Gopen2(g.get(), name.c_str(), H5P_DEFAULT), H5Gclose, file, "open " + name);
      const double t = h5::require_double(sg.get(), "t", file);
      sg.reset();
      if (t > t_last)
        h5::check(H5Ldelete(g.get(), name.c_str(), H5P_DEFAULT), file, "cannot drop snapshot " + name);
      else
        impl->next_snapshot = std::max(impl->next_snapshot, std::stoll(name) + 1);
    }
  }
  if (h5::exists(impl->f.get(), "mesh/connectivity_p2"))
    impl->num_elements = static_cast<long long>(h5::dataset_dims(impl->f.get(), "mesh/connectivity_p2", file)[0]);
  CaseWriter w(std::move(impl));
  w.append(series);
  if (w.impl_->num_elements >= 0) w.impl_->rewrite_xdmf();
  return w;
}

CaseWriter::CaseWriter(CaseWriter&&) noexcept = default;
CaseWriter& CaseWriter::operator=(CaseWriter&& other) noexcept {
  // Close (and so write the buffered rows of) the file this writer held before taking the other one.
  if (this != &other) {
    if (impl_ && impl_->f.valid()) {
      try {
        close();
      } catch (const std::exception& e) {
        std::fprintf(stderr, "capsim: closing case file: %s\n", e.what());
      }
    }
    impl_ = std::move(other.impl_);
  }
  return *this;
}

CaseWriter::~CaseWriter() {
  if (!impl_ || !impl_->f.valid()) return;
  try {
    close();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "capsim: closing case file: %s\n", e.what());
  }
}

void CaseWriter::append(const diagnostics::StepRecord& record) {
  if (!impl_->f.valid()) throw IoError(impl_->file, "case file already closed");
  impl_->pending.push_back(record);
  if (impl_->pending.size() >= impl_->options.buffer_rows) impl_->write_pending();
}

void CaseWriter::append(const diagnostics::TimeSeries& series, std::size_t from) {
  if (!series.consistent()) throw std::invalid_argument("CaseWriter::append: inconsistent time series");
  for (std::size_t i = from; i < series.size(); ++i) append(series.at(i));
}

void CaseWriter::set_attribute(const Attribute& attribute) {
  if (!impl_->f.valid()) throw IoError(impl_->file, "case file already closed");
  for (const char* r : kReserved)
    if (attribute.key == r) throw std::invalid_argument("case file attribute name '" + attribute.key + "' is reserved");
  h5::write_attribute(impl_->f.get(), attribute, impl_->file);
}

void CaseWriter::write_snapshot(double t, std::int64_t step, const mesh::SurfaceMesh& mesh,
                                const Eigen::Matrix3Xd& x, std::span<const NodeField> fields,
                                const diagnostics::StepRecord* record) {
  auto& im = *impl_;
  if (!im.f.valid()) throw IoError(im.file, "case file already closed");
  const long long n = x.cols();
  if (n != mesh.num_nodes()) throw std::invalid_argument("write_snapshot: positions do not match the mesh");
  for (const auto& fld : fields) {
    if (!valid_field_name(fld.name))
      throw std::invalid_argument("write_snapshot: bad field name '" + fld.name + "' (letters, digits, _ and -)");
    if (fld.values.cols() != n || (fld.values.rows() != 1 && fld.values.rows() != 3))
      throw std::invalid_argument("write_snapshot: field '" + fld.name + "' must be 1×N or 3×N");
  }
  if (im.num_elements < 0) {
    // Topology, once: P2 connectivity and its split into 4 flat triangles per element.
    std::vector<int> p2, lin;
    p2.reserve(mesh.elements.size() * 6);
    lin.reserve(mesh.elements.size() * 12);
    for (const auto& e : mesh.elements) {
      p2.insert(p2.end(), e.begin(), e.end());
      // Corner triangles and the middle one, all counter-clockwise from outside like the parent.
      const int tris[4][3] = {{e[0], e[3], e[5]}, {e[3], e[1], e[4]}, {e[5], e[4], e[2]}, {e[3], e[4], e[5]}};
      for (const auto& tri : tris) lin.insert(lin.end(), tri, tri + 3);
    }
    const auto ne = static_cast<hsize_t>(mesh.elements.size());
    h5::write_dataset(im.f.get(), "mesh/connectivity_p2", {ne, 6}, p2.data(), im.file);
    h5::write_dataset(im.f.get(), "mesh/connectivity_linear", {4 * ne, 3}, lin.data(), im.file);
    im.num_elements = static_cast<long long>(ne);
  } else if (im.num_elements != mesh.num_elements()) {
    throw std::invalid_argument("write_snapshot: the mesh topology changed between snapshots");
  }
  char name[32];
  std::snprintf(name, sizeof name, "snapshots/%06lld", im.next_snapshot);
  const std::string group = name;
  {
    h5::Handle g = h5::checked(H5Gcreate2(im.f.get(), group.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                               H5Gclose, im.file, "cannot create group " + group);
    h5::write_attribute(g.get(), Attribute("t", t), im.file);
    h5::write_attribute(g.get(), Attribute("step", static_cast<long long>(step)), im.file);
    if (record) {
      // The state's row of the time series, column by column (t is the attribute above).
      diagnostics::TimeSeries row;
      row.push_back(*record);
      for (const auto& c : kColumns)
        if (std::string(c.name) != "t") h5::write_attribute(g.get(), Attribute(c.name, (row.*c.member)[0]), im.file);
    }
    // Eigen 3×N column-major is exactly N×3 row-major.
    const Eigen::Matrix3Xd xc = x;
    h5::write_dataset(g.get(), "positions", {static_cast<hsize_t>(n), 3}, xc.data(), im.file);
    for (const auto& fld : fields) {
      const Eigen::MatrixXd v = fld.values;
      if (v.rows() == 1)
        h5::write_dataset(g.get(), fld.name, {static_cast<hsize_t>(n)}, v.data(), im.file);
      else
        h5::write_dataset(g.get(), fld.name, {static_cast<hsize_t>(n), 3}, v.data(), im.file);
    }
  }
  ++im.next_snapshot;
  flush();
  im.rewrite_xdmf();
}

void CaseWriter::flush() {
  if (!impl_->f.valid()) throw IoError(impl_->file, "case file already closed");
  impl_->write_pending();
  h5::check(H5Fflush(impl_->f.get(), H5F_SCOPE_GLOBAL), impl_->file, "cannot flush");
}

void CaseWriter::close() {
  if (!impl_->f.valid()) return;
  impl_->write_pending();
  impl_->f.close(impl_->file, "cannot close the case file");
}

const std::filesystem::path& CaseWriter::file() const { return impl_->file; }
std::filesystem::path CaseWriter::xdmf_file() const { return impl_->xdmf_path(); }
std::size_t CaseWriter::rows() const { return impl_->written + impl_->pending.size(); }

CaseFileContents read_case_file(const std::filesystem::path& file) {
  h5::silence_errors();
  h5::Handle f = open_file_checked(file, H5F_ACC_RDONLY);
  check_case_format(f.get(), file);
  CaseFileContents c;
  c.attributes = h5::read_attributes(f.get(), file);
  const auto dims = h5::dataset_dims(f.get(), ts("t"), file);
  if (dims.size() != 1) throw IoError(file, "dataset timeseries/t is not 1-D");
  const std::size_t n = dims[0];
  for (const auto& col : kColumns) {
    auto& v = c.series.*col.member;
    v.assign(n, 0.0);
    if (col.optional && !h5::exists(f.get(), ts(col.name))) {
      v.assign(n, col.absent);
      continue;
    }
    h5::read_dataset(f.get(), ts(col.name), n, v.data(), file);
  }
  c.series.P.resize(n);
  h5::read_dataset(f.get(), ts("P"), 3 * n, n ? c.series.P.front().data() : nullptr, file);
  h5::Handle g = h5::checked(H5Gopen2(f.get(), "snapshots", H5P_DEFAULT), H5Gclose, file, "missing group snapshots");
  c.num_snapshots = static_cast<int>(link_names(g.get(), file).size());
  return c;
}

Snapshot read_snapshot(const std::filesystem::path& file, int index) {
  h5::silence_errors();
  h5::Handle f = open_file_checked(file, H5F_ACC_RDONLY);
  check_case_format(f.get(), file);
  h5::Handle g = h5::checked(H5Gopen2(f.get(), "snapshots", H5P_DEFAULT), H5Gclose, file, "missing group snapshots");
  const auto names = link_names(g.get(), file);
  if (index < 0 || index >= static_cast<int>(names.size()))
    throw IoError(file, "no snapshot " + std::to_string(index) + " (" + std::to_string(names.size()) + " stored)");
  h5::Handle sg = h5::checked(H5Gopen2(g.get(), names[index].c_str(), H5P_DEFAULT), H5Gclose, file, "open snapshot");
  Snapshot s;
  s.t = h5::require_double(sg.get(), "t", file);
  s.step = h5::require_int(sg.get(), "step", file);
  for (auto& a : h5::read_attributes(sg.get(), file))
    if (a.key != "t" && a.key != "step") s.attributes.push_back(std::move(a));
  const auto pd = h5::dataset_dims(sg.get(), "positions", file);
  if (pd.size() != 2 || pd[1] != 3) throw IoError(file, "snapshot positions are not N×3");
  s.positions.resize(3, static_cast<Eigen::Index>(pd[0]));
  h5::read_dataset(sg.get(), "positions", 3 * pd[0], s.positions.data(), file);
  const auto cd = h5::dataset_dims(f.get(), "mesh/connectivity_p2", file);
  if (cd.size() != 2 || cd[1] != 6) throw IoError(file, "mesh/connectivity_p2 is not E×6");
  s.elements.resize(cd[0]);
  h5::read_dataset(f.get(), "mesh/connectivity_p2", 6 * cd[0], cd[0] ? s.elements.front().data() : nullptr, file);
  for (const auto& name : link_names(sg.get(), file)) {
    if (name == "positions") continue;
    const auto d = h5::dataset_dims(sg.get(), name, file);
    const Eigen::Index rows = d.size() == 2 ? static_cast<Eigen::Index>(d[1]) : 1;
    NodeField fld{name, Eigen::MatrixXd(rows, static_cast<Eigen::Index>(d[0]))};
    h5::read_dataset(sg.get(), name, static_cast<std::size_t>(fld.values.size()), fld.values.data(), file);
    s.fields.push_back(std::move(fld));
  }
  return s;
}

}  // namespace capsim::io
