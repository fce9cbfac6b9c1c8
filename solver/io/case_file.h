#pragma once
/// @file
/// @brief The case file: one HDF5 file per case holding the diagnostics time series, the case parameters
/// and code version as attributes, and optional snapshots of the membrane with an XDMF (.xmf) companion
/// that ParaView opens directly.
///
/// Layout (every length in units of ℓ, time in 1/γ̇, tensions in Gs):
///   /                      attributes: format = "capsim-case", format_version = 1, code_version (git commit),
///                          capsim_version, then the caller's parameters/results (numbers or strings)
///   /timeseries/{t, D12, L1, L2, theta, tau_min, volume, area, bending_energy, max_bending_moment,
///                axis_x1..3, axis_tilt, axis_azimuth, La, Lb, Lc, ea_x1..3, eb_x1..3, ec_x1..3, spin}
///                          float64 [n], extendible, chunked; attributes `units` and `description` (the table
///                          kColumns in case_file.cc; solver/README.md §5). Columns added after the first files
///                          are optional: a file without them reads as 0 or NaN (kColumns says which)
///   /timeseries/P          float64 [n, 3]
///   /mesh/connectivity_p2  int32 [E, 6] P2 elements (vertices 0,1,2; mid-sides 0–1, 1–2, 2–0), written with
///                          the first snapshot; /mesh/connectivity_linear int32 [4E, 3]: each P2 triangle
///                          split into 4 flat ones, for tools without quadratic cells
///   /snapshots/NNNNNN      attributes t, step and (when the writer passes the state's record) every other 1-D
///                          time-series column of that state under its column name (D12, theta, La, ea_x1, spin,
///                          ...: units as in /timeseries); positions float64 [N, 3]; one dataset per node field,
///                          float64 [N] (scalar) or [N, 3] (vector)
/// The .xmf file (same name, extension .xmf) is a temporal collection over the snapshots with the P2
/// topology (XDMF Triangle_6, same node order as ours) or the linear split; it is rewritten at each snapshot.
/// h5py: `f["timeseries/D12"][:]`, `dict(f.attrs)`.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "solver/diagnostics/time_series.h"
#include "solver/io/attribute.h"
#include "solver/mesh/mesh.h"

namespace capsim::io {

/// @brief Format version of the case file written by this build.
inline constexpr std::int64_t kCaseFormatVersion = 1;

/// @brief A per-node field of a snapshot: 1 row (scalar, e.g. q·n, τ1, τ2) or 3 rows (vector, e.g. q),
/// one column per node.
struct NodeField {
  std::string name;        ///< dataset name: letters, digits, '_' and '-' only
  Eigen::MatrixXd values;  ///< 1 × N or 3 × N

  /// @brief A scalar field.
  static NodeField scalar(std::string name, const Eigen::VectorXd& v) {
    return {std::move(name), v.transpose()};
  }
  /// @brief A vector field.
  static NodeField vector(std::string name, const Eigen::Matrix3Xd& v) { return {std::move(name), v}; }
};

/// @brief Cell type of the snapshots in the .xmf file.
enum class XdmfTopology {
  Triangle6,    ///< the P2 elements as XDMF Triangle_6 (curved, ParaView tessellates them)
  LinearSplit,  ///< each P2 element as 4 flat triangles
};

/// @brief Options of a case file.
struct CaseFileOptions {
  std::size_t buffer_rows = 256;  ///< time-series rows kept in memory before they are written
  std::size_t chunk_rows = 1024;  ///< HDF5 chunk length of the time series
  XdmfTopology topology = XdmfTopology::Triangle6;
};

/// @brief Writes one case file. Not thread-safe (HDF5 is the serial build): use it from the time loop.
class CaseWriter {
 public:
  /// @brief Create (or truncate) `file` with the given parameters as root attributes.
  /// @throws IoError (e.g. directory missing, file not writable); std::invalid_argument if a parameter
  /// reuses a reserved name (format, format_version, code_version, capsim_version).
  CaseWriter(const std::filesystem::path& file, const std::vector<Attribute>& parameters,
             const CaseFileOptions& options = {});

  /// @brief Reopen an existing case file to continue a run restarted from a checkpoint: the time series is
  /// replaced by `series` (the checkpoint's), snapshots later than its last time are dropped (from the
  /// index and the .xmf; HDF5 does not reclaim their space). Creates the file if it is missing.
  static CaseWriter resume(const std::filesystem::path& file, const std::vector<Attribute>& parameters,
                           const diagnostics::TimeSeries& series, const CaseFileOptions& options = {});

  /// @brief Movable; a moved-from writer must not be used. Assigning over an open writer closes its file.
  CaseWriter(CaseWriter&&) noexcept;
  CaseWriter& operator=(CaseWriter&&) noexcept;
  /// @brief Closes the file (errors are reported on stderr; call close() to get them as exceptions).
  ~CaseWriter();

  /// @brief Append one step (buffered).
  void append(const diagnostics::StepRecord& record);
  /// @brief Append records [from, size) of a series (buffered).
  void append(const diagnostics::TimeSeries& series, std::size_t from = 0);
  /// @brief Write or replace a root attribute (e.g. results: min_D12, regime, status at the end).
  void set_attribute(const Attribute& attribute);
  /// @brief Write a snapshot of the membrane at time t and rewrite the .xmf file. The mesh topology must be
  /// the same at every snapshot. With @p record (the diagnostics of x), its time-series columns but t become
  /// attributes of the snapshot, so that a snapshot says its shape's ellipsoid, axis and spin without the series.
  /// @throws std::invalid_argument on mismatched sizes or a bad field name.
  void write_snapshot(double t, std::int64_t step, const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x,
                      std::span<const NodeField> fields = {}, const diagnostics::StepRecord* record = nullptr);
  /// @brief Write buffered rows and flush the file to disk.
  void flush();
  /// @brief Flush and close; the writer is unusable afterwards.
  void close();

  /// @brief Path of the HDF5 file.
  [[nodiscard]] const std::filesystem::path& file() const;
  /// @brief Path of the .xmf file (exists once a snapshot has been written).
  [[nodiscard]] std::filesystem::path xdmf_file() const;
  /// @brief Rows written or buffered so far.
  [[nodiscard]] std::size_t rows() const;

 private:
  struct Impl;
  explicit CaseWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// @brief Contents of a case file, as read back.
struct CaseFileContents {
  std::vector<Attribute> attributes;  ///< all root attributes (reserved ones included), by name
  diagnostics::TimeSeries series;
  int num_snapshots = 0;
};

/// @brief Read a case file's attributes and time series.
/// @throws IoError if the file is missing, not a capsim case file, or inconsistent.
CaseFileContents read_case_file(const std::filesystem::path& file);

/// @brief One snapshot, as read back.
struct Snapshot {
  double t = 0;
  std::int64_t step = 0;
  Eigen::Matrix3Xd positions;
  std::vector<std::array<int, 6>> elements;
  std::vector<NodeField> fields;
  /// The state's time-series columns written with it (CaseWriter::write_snapshot's record), by name; empty for a
  /// snapshot written without (a blow-up's last good state, files from before them).
  std::vector<Attribute> attributes;
};

/// @brief Read snapshot `index` (0-based, in writing order) of a case file.
/// @throws IoError if missing.
Snapshot read_snapshot(const std::filesystem::path& file, int index);

}  // namespace capsim::io
