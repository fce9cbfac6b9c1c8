#pragma once
/// @file
/// @brief The exception of the io layer: every failure to write or read a case file or a checkpoint
/// (HDF5 errors, missing or inconsistent data, corrupt or truncated files) names the file.

#include <filesystem>
#include <stdexcept>
#include <string>

namespace capsim::io {

/// @brief An input/output failure on `file()`; what() is one readable line that names the file.
class IoError : public std::runtime_error {
 public:
  IoError(const std::filesystem::path& file, const std::string& message)
      : std::runtime_error(file.string() + ": " + message), file_(file) {}
  /// @brief The file concerned.
  [[nodiscard]] const std::filesystem::path& file() const { return file_; }

 private:
  std::filesystem::path file_;
};

}  // namespace capsim::io
