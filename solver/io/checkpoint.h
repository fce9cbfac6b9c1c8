#pragma once
/// @file
/// @brief Checkpoints: everything the time loop needs to continue a case exactly, written atomically and
/// validated on read.
///
/// Writing goes to a temporary file in the same directory, which is flushed, fsync'ed and renamed over
/// the target: a crash at any moment leaves either the previous checkpoint or the new one, never a mix.
/// Reading checks the format name and version, the presence, shapes and mutual consistency of every
/// dataset, and a 64-bit checksum (FNV-1a) over all the stored values, so a corrupt or truncated file gives
/// an IoError naming the file instead of a wrong restart. Values are stored as IEEE binary64 / int64 and
/// read back bitwise identical.
///
/// Layout: root attributes format = "capsim-checkpoint", format_version, code_version, time, step, dt,
/// num_nodes, num_records, checksum; datasets positions [N, 3], timeseries/{t, D12, …, spin} [n] (every 1-D
/// column of diagnostics::TimeSeries; those added later are optional, read as 0 or NaN from older checkpoints),
/// timeseries/P [n, 3]; groups scalars and strings whose attributes are the opaque key/value maps.

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

#include <Eigen/Core>

#include "solver/diagnostics/time_series.h"

namespace capsim::io {

/// @brief The checkpoint's file name in a case's output folder (`capsim run --out DIR`): DIR/checkpoint.h5.
inline constexpr const char* kCheckpointFileName = "checkpoint.h5";

/// @brief Format version of the checkpoints written by this build.
inline constexpr std::int64_t kCheckpointFormatVersion = 1;

/// @brief State of a case at the end of a step.
struct Checkpoint {
  Eigen::Matrix3Xd positions;            ///< node positions, one column per node
  double time = 0;                       ///< t at the end of `step`
  std::int64_t step = 0;                 ///< steps done
  double dt = 0;                         ///< time step in use
  diagnostics::TimeSeries series;        ///< diagnostics so far (the period analysis needs the history)
  std::map<std::string, double> scalars; ///< opaque to io: e.g. material point node, initial volume, case hash
  std::map<std::string, std::string> strings;  ///< opaque strings (e.g. the case identity)
};

/// @brief Write `checkpoint` to `file` atomically (temporary file + rename).
/// @throws IoError (the previous file, if any, is left untouched); std::invalid_argument for an inconsistent
/// series or an empty key.
void write_checkpoint(const std::filesystem::path& file, const Checkpoint& checkpoint);

/// @brief Read and validate a checkpoint.
/// @throws IoError naming the file if it is missing, not HDF5, truncated, of another format or version,
/// lacks a dataset, has inconsistent sizes, or fails the checksum.
Checkpoint read_checkpoint(const std::filesystem::path& file);

/// @brief Bitwise equality (NaN payloads included), for tests and resume checks.
bool bitwise_equal(const Checkpoint& a, const Checkpoint& b);

}  // namespace capsim::io
