#include "solver/io/hdf5_support.h"

#include <algorithm>
#include <mutex>
#include <numeric>

namespace capsim::io::h5 {
namespace {

herr_t collect_error(unsigned /*n*/, const H5E_error2_t* err, void* data) {
  auto* out = static_cast<std::vector<std::string>*>(data);
  std::string msg = err->desc ? err->desc : "";
  if (err->func_name) msg = std::string(err->func_name) + ": " + msg;
  out->push_back(msg);
  return 0;
}

Handle scalar_space(const std::filesystem::path& file) {
  return checked(H5Screate(H5S_SCALAR), H5Sclose, file, "cannot create a dataspace");
}

Handle vlen_string_type(const std::filesystem::path& file) {
  Handle t = checked(H5Tcopy(H5T_C_S1), H5Tclose, file, "cannot create a string type");
  check(H5Tset_size(t.get(), H5T_VARIABLE), file, "cannot create a string type");
  check(H5Tset_cset(t.get(), H5T_CSET_UTF8), file, "cannot create a string type");
  return t;
}

Handle link_create_plist(const std::filesystem::path& file) {
  Handle p = checked(H5Pcreate(H5P_LINK_CREATE), H5Pclose, file, "cannot create a property list");
  check(H5Pset_create_intermediate_group(p.get(), 1), file, "cannot create a property list");
  return p;
}

std::size_t product(const std::vector<hsize_t>& dims) {
  return std::accumulate(dims.begin(), dims.end(), std::size_t{1},
                         [](std::size_t a, hsize_t b) { return a * static_cast<std::size_t>(b); });
}

template <class T>
void write_any(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims, const T* data, hid_t file_type,
               hid_t mem_type, const std::filesystem::path& file) {
  Handle space = checked(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose, file,
                         "cannot create the dataspace of " + name);
  Handle lcpl = link_create_plist(file);
  Handle d = checked(H5Dcreate2(loc, name.c_str(), file_type, space.get(), lcpl.get(), H5P_DEFAULT, H5P_DEFAULT),
                     H5Dclose, file, "cannot create dataset " + name);
  if (product(dims) > 0)
    check(H5Dwrite(d.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), file, "cannot write dataset " + name);
}

template <class T>
void read_any(hid_t loc, const std::string& name, std::size_t count, T* data, hid_t mem_type, H5T_class_t cls,
              const std::filesystem::path& file) {
  const auto dims = dataset_dims(loc, name, file);
  if (product(dims) != count)
    throw IoError(file, "dataset " + name + " has " + std::to_string(product(dims)) + " values, expected " +
                            std::to_string(count));
  Handle d = checked(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose, file, "cannot open dataset " + name);
  Handle type = checked(H5Dget_type(d.get()), H5Tclose, file, "cannot read the type of dataset " + name);
  if (H5Tget_class(type.get()) != cls) throw IoError(file, "dataset " + name + " has the wrong type");
  if (count > 0)
    check(H5Dread(d.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), file, "cannot read dataset " + name);
}

}  // namespace

void silence_errors() {
  static std::once_flag once;
  std::call_once(once, [] { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); });
}

void fail(const std::filesystem::path& file, const std::string& what) {
  std::vector<std::string> stack;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, collect_error, &stack);
  H5Eclear2(H5E_DEFAULT);
  std::string msg = what;
  if (!stack.empty()) {
    // The innermost entries carry the specific cause ("truncated file: eof = …", "bad symbol table node
    // signature", …); the outer ones only repeat the API call.
    msg += " (HDF5: " + stack.back();
    if (stack.size() >= 2 && stack[stack.size() - 2] != stack.back()) msg += "; " + stack[stack.size() - 2];
    msg += ")";
  }
  throw IoError(file, msg);
}

void Handle::close(const std::filesystem::path& file, const std::string& what) {
  if (id_ < 0) return;
  const herr_t s = close_ ? close_(id_) : 0;
  id_ = H5I_INVALID_HID;
  check(s, file, what);
}

Handle checked(hid_t id, Handle::Closer close, const std::filesystem::path& file, const std::string& what) {
  if (id < 0) fail(file, what);
  return Handle(id, close);
}

void check(herr_t status, const std::filesystem::path& file, const std::string& what) {
  if (status < 0) fail(file, what);
}

bool exists(hid_t loc, const std::string& name) {
  // H5Lexists fails (rather than returning false) when an intermediate group is missing: walk the path.
  std::string prefix = name.starts_with('/') ? "/" : "";
  std::size_t start = prefix.size();
  while (start <= name.size()) {
    const std::size_t slash = name.find('/', start);
    const std::string part = name.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
    prefix += (prefix.empty() || prefix.back() == '/' ? "" : "/") + part;
    if (H5Lexists(loc, prefix.c_str(), H5P_DEFAULT) <= 0) {
      H5Eclear2(H5E_DEFAULT);
      return false;
    }
    if (slash == std::string::npos) break;
    start = slash + 1;
  }
  return true;
}

void write_attribute(hid_t obj, const Attribute& a, const std::filesystem::path& file, StringStorage strings) {
  if (a.key.empty()) throw IoError(file, "attribute with an empty name");
  if (H5Aexists(obj, a.key.c_str()) > 0)
    check(H5Adelete(obj, a.key.c_str()), file, "cannot replace attribute " + a.key);
  Handle space = scalar_space(file);
  if (const auto* d = std::get_if<double>(&a.value)) {
    Handle at = checked(H5Acreate2(obj, a.key.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                        H5Aclose, file, "cannot create attribute " + a.key);
    check(H5Awrite(at.get(), H5T_NATIVE_DOUBLE, d), file, "cannot write attribute " + a.key);
  } else if (const auto* i = std::get_if<std::int64_t>(&a.value)) {
    Handle at = checked(H5Acreate2(obj, a.key.c_str(), H5T_STD_I64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                        H5Aclose, file, "cannot create attribute " + a.key);
    check(H5Awrite(at.get(), H5T_NATIVE_INT64, i), file, "cannot write attribute " + a.key);
  } else {
    const std::string& s = std::get<std::string>(a.value);
    if (strings == StringStorage::Variable) {
      Handle type = vlen_string_type(file);
      Handle at = checked(H5Acreate2(obj, a.key.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
                          H5Aclose, file, "cannot create attribute " + a.key);
      const char* p = s.c_str();
      check(H5Awrite(at.get(), type.get(), &p), file, "cannot write attribute " + a.key);
    } else {
      // Null-padded to at least one byte (HDF5 has no zero-size string type); trailing NULs are stripped on read.
      Handle type = checked(H5Tcopy(H5T_C_S1), H5Tclose, file, "cannot create a string type");
      check(H5Tset_size(type.get(), std::max<std::size_t>(s.size(), 1)), file, "cannot create a string type");
      check(H5Tset_strpad(type.get(), H5T_STR_NULLPAD), file, "cannot create a string type");
      check(H5Tset_cset(type.get(), H5T_CSET_UTF8), file, "cannot create a string type");
      Handle at = checked(H5Acreate2(obj, a.key.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
                          H5Aclose, file, "cannot create attribute " + a.key);
      std::string buf = s;
      buf.resize(std::max<std::size_t>(s.size(), 1), '\0');
      check(H5Awrite(at.get(), type.get(), buf.data()), file, "cannot write attribute " + a.key);
    }
  }
}

std::optional<Attribute> read_attribute(hid_t obj, const std::string& key, const std::filesystem::path& file) {
  const htri_t ex = H5Aexists(obj, key.c_str());
  if (ex < 0) fail(file, "cannot look up attribute " + key);
  if (ex == 0) return std::nullopt;
  Handle at = checked(H5Aopen(obj, key.c_str(), H5P_DEFAULT), H5Aclose, file, "cannot open attribute " + key);
  Handle space = checked(H5Aget_space(at.get()), H5Sclose, file, "cannot read attribute " + key);
  if (H5Sget_simple_extent_npoints(space.get()) != 1) throw IoError(file, "attribute " + key + " is not a scalar");
  Handle type = checked(H5Aget_type(at.get()), H5Tclose, file, "cannot read the type of attribute " + key);
  switch (H5Tget_class(type.get())) {
    case H5T_FLOAT: {
      double v = 0;
      check(H5Aread(at.get(), H5T_NATIVE_DOUBLE, &v), file, "cannot read attribute " + key);
      return Attribute(key, v);
    }
    case H5T_INTEGER: {
      std::int64_t v = 0;
      check(H5Aread(at.get(), H5T_NATIVE_INT64, &v), file, "cannot read attribute " + key);
      return Attribute(key, static_cast<long long>(v));
    }
    case H5T_STRING: {
      if (H5Tis_variable_str(type.get()) > 0) {
        Handle mem = vlen_string_type(file);
        char* p = nullptr;
        check(H5Aread(at.get(), mem.get(), &p), file, "cannot read attribute " + key);
        std::string s = p ? p : "";
        H5free_memory(p);
        return Attribute(key, std::move(s));
      }
      const std::size_t size = H5Tget_size(type.get());
      if (size == 0 || size > (1u << 24)) throw IoError(file, "attribute " + key + " has an implausible size");
      std::string s(size, '\0');
      // Read with the stored type itself: no conversion (HDF5 has none between ASCII and UTF-8).
      check(H5Aread(at.get(), type.get(), s.data()), file, "cannot read attribute " + key);
      s.resize(s.find('\0') == std::string::npos ? s.size() : s.find('\0'));
      return Attribute(key, std::move(s));
    }
    default:
      throw IoError(file, "attribute " + key + " is neither a number nor a string");
  }
}

std::vector<Attribute> read_attributes(hid_t obj, const std::filesystem::path& file) {
  std::vector<std::string> names;
  auto cb = [](hid_t, const char* name, const H5A_info_t*, void* data) -> herr_t {
    static_cast<std::vector<std::string>*>(data)->emplace_back(name);
    return 0;
  };
  hsize_t idx = 0;
  check(H5Aiterate2(obj, H5_INDEX_NAME, H5_ITER_INC, &idx, cb, &names), file, "cannot list attributes");
  std::vector<Attribute> out;
  for (const auto& n : names)
    if (auto a = read_attribute(obj, n, file)) out.push_back(std::move(*a));
  return out;
}

double require_double(hid_t obj, const std::string& key, const std::filesystem::path& file) {
  const auto a = read_attribute(obj, key, file);
  if (!a) throw IoError(file, "missing attribute " + key);
  if (const auto* d = std::get_if<double>(&a->value)) return *d;
  throw IoError(file, "attribute " + key + " is not a floating-point number");
}

std::int64_t require_int(hid_t obj, const std::string& key, const std::filesystem::path& file) {
  const auto a = read_attribute(obj, key, file);
  if (!a) throw IoError(file, "missing attribute " + key);
  if (const auto* i = std::get_if<std::int64_t>(&a->value)) return *i;
  throw IoError(file, "attribute " + key + " is not an integer");
}

std::string require_string(hid_t obj, const std::string& key, const std::filesystem::path& file) {
  const auto a = read_attribute(obj, key, file);
  if (!a) throw IoError(file, "missing attribute " + key);
  if (const auto* s = std::get_if<std::string>(&a->value)) return *s;
  throw IoError(file, "attribute " + key + " is not a string");
}

void write_dataset(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims, const double* data,
                   const std::filesystem::path& file) {
  write_any(loc, name, dims, data, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, file);
}

void write_dataset(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims, const int* data,
                   const std::filesystem::path& file) {
  write_any(loc, name, dims, data, H5T_STD_I32LE, H5T_NATIVE_INT, file);
}

std::vector<hsize_t> dataset_dims(hid_t loc, const std::string& name, const std::filesystem::path& file) {
  if (!exists(loc, name)) throw IoError(file, "missing dataset " + name);
  Handle d = checked(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose, file, "cannot open dataset " + name);
  Handle space = checked(H5Dget_space(d.get()), H5Sclose, file, "cannot read the shape of dataset " + name);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 0) fail(file, "cannot read the shape of dataset " + name);
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  if (rank > 0 && H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr) < 0)
    fail(file, "cannot read the shape of dataset " + name);
  return dims;
}

void read_dataset(hid_t loc, const std::string& name, std::size_t count, double* data,
                  const std::filesystem::path& file) {
  read_any(loc, name, count, data, H5T_NATIVE_DOUBLE, H5T_FLOAT, file);
}

void read_dataset(hid_t loc, const std::string& name, std::size_t count, int* data,
                  const std::filesystem::path& file) {
  read_any(loc, name, count, data, H5T_NATIVE_INT, H5T_INTEGER, file);
}

void create_extendible(hid_t loc, const std::string& name, hsize_t cols, hsize_t chunk_rows,
                       const std::filesystem::path& file) {
  const int rank = cols == 0 ? 1 : 2;
  const hsize_t dims[2] = {0, cols}, maxdims[2] = {H5S_UNLIMITED, cols}, chunk[2] = {chunk_rows, cols};
  Handle space = checked(H5Screate_simple(rank, dims, maxdims), H5Sclose, file, "cannot create the dataspace of " + name);
  Handle dcpl = checked(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, file, "cannot create a property list");
  check(H5Pset_chunk(dcpl.get(), rank, chunk), file, "cannot set the chunks of " + name);
  Handle lcpl = link_create_plist(file);
  Handle d = checked(H5Dcreate2(loc, name.c_str(), H5T_IEEE_F64LE, space.get(), lcpl.get(), dcpl.get(), H5P_DEFAULT),
                     H5Dclose, file, "cannot create dataset " + name);
}

void set_rows(hid_t loc, const std::string& name, hsize_t cols, std::size_t rows,
              const std::filesystem::path& file) {
  Handle d = checked(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose, file, "cannot open dataset " + name);
  const hsize_t dims[2] = {rows, cols};
  check(H5Dset_extent(d.get(), dims), file, "cannot resize dataset " + name);
}

void append_rows(hid_t loc, const std::string& name, hsize_t cols, std::size_t rows, const double* data,
                 const std::filesystem::path& file) {
  if (rows == 0) return;
  const int rank = cols == 0 ? 1 : 2;
  Handle d = checked(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose, file, "cannot open dataset " + name);
  hsize_t old[2] = {0, cols};
  {
    Handle space = checked(H5Dget_space(d.get()), H5Sclose, file, "cannot read the shape of " + name);
    if (H5Sget_simple_extent_ndims(space.get()) != rank) throw IoError(file, "dataset " + name + " has the wrong rank");
    check(H5Sget_simple_extent_dims(space.get(), old, nullptr), file, "cannot read the shape of " + name);
  }
  const hsize_t grown[2] = {old[0] + rows, cols};
  check(H5Dset_extent(d.get(), grown), file, "cannot extend dataset " + name);
  Handle fspace = checked(H5Dget_space(d.get()), H5Sclose, file, "cannot read the shape of " + name);
  const hsize_t start[2] = {old[0], 0}, count[2] = {rows, cols};
  check(H5Sselect_hyperslab(fspace.get(), H5S_SELECT_SET, start, nullptr, count, nullptr), file,
        "cannot select rows of " + name);
  Handle mspace = checked(H5Screate_simple(rank, count, nullptr), H5Sclose, file, "cannot create a dataspace");
  check(H5Dwrite(d.get(), H5T_NATIVE_DOUBLE, mspace.get(), fspace.get(), H5P_DEFAULT, data), file,
        "cannot append to dataset " + name);
}

}  // namespace capsim::io::h5
