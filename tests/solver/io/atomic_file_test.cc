// The one atomic file writer: replaces whole files, leaves the old one and no temporary on failure.
#include "solver/io/atomic_file.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include <gtest/gtest.h>

#include "solver/io/io_error.h"

namespace capsim::io {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(CAPSIM_TEST_TMP) / "io_atomic" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string contents(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

int entries(const fs::path& dir) { return static_cast<int>(std::distance(fs::directory_iterator(dir), {})); }

TEST(AtomicFile, WritesAndReplacesWholeFiles) {
  const auto dir = scratch("replace");
  write_text_atomically(dir / "a.txt", "first");
  EXPECT_EQ(contents(dir / "a.txt"), "first");
  write_text_atomically(dir / "a.txt", "second, longer");
  EXPECT_EQ(contents(dir / "a.txt"), "second, longer");
  EXPECT_EQ(entries(dir), 1) << "no temporary left behind";
}

TEST(AtomicFile, FailedWriterLeavesTheOldFileAndNoTemporary) {
  const auto dir = scratch("failed");
  write_text_atomically(dir / "a.txt", "old");
  EXPECT_THROW(replace_file_atomically(dir / "a.txt",
                                       [](const fs::path& tmp) {
                                         std::ofstream(tmp) << "half";
                                         throw std::runtime_error("disk full");
                                       }),
               std::runtime_error);
  EXPECT_EQ(contents(dir / "a.txt"), "old");
  EXPECT_EQ(entries(dir), 1);
}

TEST(AtomicFile, MissingFolderIsAnIoErrorNamingTheFile) {
  const auto dir = scratch("missing");
  try {
    write_text_atomically(dir / "no" / "a.txt", "x");
    FAIL() << "no exception";
  } catch (const IoError& e) {
    EXPECT_EQ(e.file(), dir / "no" / "a.txt");
  }
}

}  // namespace
}  // namespace capsim::io
