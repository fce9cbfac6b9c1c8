#pragma once
/// @file
/// @brief Generic key/value attributes (case parameters, results) stored on HDF5 files, so the io layer does
/// not depend on the configuration structs.

#include <cstdint>
#include <string>
#include <utility>
#include <variant>

namespace capsim::io {

/// @brief A named number or string. Integers are kept apart from doubles so counts (mesh level, steps)
/// stay integers in the file.
struct Attribute {
  using Value = std::variant<double, std::int64_t, std::string>;
  std::string key;
  Value value;

  Attribute(std::string k, double v) : key(std::move(k)), value(v) {}
  Attribute(std::string k, int v) : key(std::move(k)), value(static_cast<std::int64_t>(v)) {}
  Attribute(std::string k, long v) : key(std::move(k)), value(static_cast<std::int64_t>(v)) {}
  Attribute(std::string k, long long v) : key(std::move(k)), value(static_cast<std::int64_t>(v)) {}
  Attribute(std::string k, std::string v) : key(std::move(k)), value(std::move(v)) {}
  Attribute(std::string k, const char* v) : key(std::move(k)), value(std::string(v)) {}
  Attribute(std::string k, bool v) = delete;  // ambiguous intent: store "true"/"false" or 0/1 explicitly

  friend bool operator==(const Attribute&, const Attribute&) = default;
};

}  // namespace capsim::io
