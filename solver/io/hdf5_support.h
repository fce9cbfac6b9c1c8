#pragma once
/// @file
/// @brief Internal to solver/io (includes hdf5.h, which is linked PRIVATE): RAII handles, error translation
/// to IoError, and the few dataset/attribute operations the case file and the checkpoint need.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <hdf5.h>

#include "solver/io/attribute.h"
#include "solver/io/io_error.h"

namespace capsim::io::h5 {

/// @brief Turn off HDF5's automatic printing of its error stack (we turn errors into exceptions instead).
/// Idempotent; called by every entry point of the io layer.
void silence_errors();

/// @brief Throw IoError for `file` with `what` and the innermost messages of HDF5's error stack.
[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what);

/// @brief A move-only owner of an HDF5 identifier with its close function.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer close) : id_(id), close_(close) {}
  Handle(Handle&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = H5I_INVALID_HID; }
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = o.id_;
      close_ = o.close_;
      o.id_ = H5I_INVALID_HID;
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { reset(); }
  /// @brief Close now (errors ignored: used on unwinding).
  void reset() {
    if (id_ >= 0 && close_) close_(id_);
    id_ = H5I_INVALID_HID;
  }
  /// @brief Close now and throw on failure (flushes data for files).
  void close(const std::filesystem::path& file, const std::string& what);
  [[nodiscard]] hid_t get() const { return id_; }
  [[nodiscard]] bool valid() const { return id_ >= 0; }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer close_ = nullptr;
};

/// @brief Check an identifier-returning call and wrap it, or throw.
Handle checked(hid_t id, Handle::Closer close, const std::filesystem::path& file, const std::string& what);
/// @brief Check a status-returning call, or throw.
void check(herr_t status, const std::filesystem::path& file, const std::string& what);

/// @brief True when the link `name` exists below `loc` (intermediate groups included).
bool exists(hid_t loc, const std::string& name);

// ---- attributes (on any object) ----
/// @brief How string attributes are stored.
enum class StringStorage {
  /// Variable length (h5py reads them as str). The text lives in the file's global heap, which HDF5 neither
  /// checksums nor bounds-checks: a damaged heap can crash or hang the reader. Fine for outputs.
  Variable,
  /// Fixed length, stored inside the (checksummed) object header: for files that are validated on read.
  Fixed,
};
/// @brief Write (replace) an attribute.
void write_attribute(hid_t obj, const Attribute& a, const std::filesystem::path& file,
                     StringStorage strings = StringStorage::Variable);
/// @brief Read an attribute of any of the stored kinds (double, 64-bit integer, string); nullopt if absent.
std::optional<Attribute> read_attribute(hid_t obj, const std::string& key, const std::filesystem::path& file);
/// @brief All attributes of obj in creation/name order.
std::vector<Attribute> read_attributes(hid_t obj, const std::filesystem::path& file);
/// @brief Required attribute of a given kind, or IoError naming it.
double require_double(hid_t obj, const std::string& key, const std::filesystem::path& file);
std::int64_t require_int(hid_t obj, const std::string& key, const std::filesystem::path& file);
std::string require_string(hid_t obj, const std::string& key, const std::filesystem::path& file);

// ---- datasets of doubles / ints, row-major dims ----
/// @brief Create a fixed-size dataset and write data (size = product of dims; may be 0).
void write_dataset(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims, const double* data,
                   const std::filesystem::path& file);
void write_dataset(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims, const int* data,
                   const std::filesystem::path& file);
/// @brief Dimensions of an existing dataset, or IoError naming it when missing.
std::vector<hsize_t> dataset_dims(hid_t loc, const std::string& name, const std::filesystem::path& file);
/// @brief Read a whole dataset of `count` values (checked against its dims) into data.
void read_dataset(hid_t loc, const std::string& name, std::size_t count, double* data,
                  const std::filesystem::path& file);
void read_dataset(hid_t loc, const std::string& name, std::size_t count, int* data,
                  const std::filesystem::path& file);

/// @brief Create an empty extendible chunked dataset of doubles with `cols` columns (cols = 0: 1-D).
void create_extendible(hid_t loc, const std::string& name, hsize_t cols, hsize_t chunk_rows,
                       const std::filesystem::path& file);
/// @brief Append `rows` rows (each `cols` values, cols = 0 for 1-D) to an extendible dataset.
void append_rows(hid_t loc, const std::string& name, hsize_t cols, std::size_t rows, const double* data,
                 const std::filesystem::path& file);
/// @brief Shrink or grow an extendible dataset to `rows` rows.
void set_rows(hid_t loc, const std::string& name, hsize_t cols, std::size_t rows,
              const std::filesystem::path& file);

}  // namespace capsim::io::h5
