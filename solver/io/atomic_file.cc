#include "solver/io/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

#include "solver/io/io_error.h"

namespace capsim::io {
namespace {

// fsync of a file (its data) or of a folder (the entry a rename changed).
void sync_path(const std::filesystem::path& p, bool directory, const std::filesystem::path& file) {
  const int fd = ::open(p.c_str(), directory ? O_RDONLY | O_DIRECTORY : O_RDONLY);
  if (fd < 0) {
    if (directory) return;  // best effort for folders on file systems that do not open them
    throw IoError(file, "cannot open " + p.string() + " to flush it: " + std::strerror(errno));
  }
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0 && !directory) throw IoError(file, "cannot flush " + p.string() + " to disk: " + std::strerror(err));
}

}  // namespace

void replace_file_atomically(const std::filesystem::path& file,
                             const std::function<void(const std::filesystem::path& temporary)>& write_temporary) {
  std::filesystem::path tmp = file;
  tmp += ".tmp-" + std::to_string(::getpid());
  try {
    write_temporary(tmp);
    sync_path(tmp, false, file);
    std::error_code ec;
    std::filesystem::rename(tmp, file, ec);  // atomic replacement on POSIX
    if (ec) throw IoError(file, "cannot rename " + tmp.string() + " into place: " + ec.message());
    sync_path(file.has_parent_path() ? file.parent_path() : std::filesystem::path("."), true, file);
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw;
  }
}

void write_text_atomically(const std::filesystem::path& file, const std::string& text) {
  replace_file_atomically(file, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    out.flush();
    if (!out) throw IoError(file, "cannot write (temporary file " + tmp.string() + ")");
  });
}

}  // namespace capsim::io
