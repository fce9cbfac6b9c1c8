#pragma once
/// @file
/// @brief Replacing a file atomically, the one way every writer of the code does it: the new contents go to
/// a temporary file in the same folder (same file system, so the rename cannot degrade to a copy), are
/// flushed to disk (fsync), and the temporary file is renamed over the target; the folder is then synced so
/// the rename itself survives a crash. A reader sees the old file or the new one, never half of either, and
/// a failed write leaves the old file and no temporary behind.

#include <filesystem>
#include <functional>
#include <string>

namespace capsim::io {

/// @brief Replace @p file with what @p write_temporary writes to the temporary path it is given (for
/// writers that need a path, such as HDF5). The temporary is "<file>.tmp-<pid>".
/// @throws IoError naming @p file if the temporary cannot be synced or renamed; whatever
/// @p write_temporary throws (the temporary is removed in both cases).
void replace_file_atomically(const std::filesystem::path& file,
                             const std::function<void(const std::filesystem::path& temporary)>& write_temporary);

/// @brief Replace @p file with @p text atomically.
/// @throws IoError naming @p file if it cannot be written (folder missing, disk full, permissions).
void write_text_atomically(const std::filesystem::path& file, const std::string& text);

}  // namespace capsim::io
