#pragma once
/// @file
/// @brief The parameters of one capsule case, read from a TOML case file with `--set section.key=value`
/// overrides and validated before anything runs. The keys are those of the registry (case_keys.def);
/// schemas/case_keys.md is generated from it.

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "solver/config/case_enums.h"

namespace capsim::config {

/// @brief Bad input in a case file or override: the message names the key or the file.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// @brief Everything that defines one case: one field per entry of the key registry (case_keys.def, where
/// each key's meaning, default and accepted values are documented), with the registry's default. The
/// struct is generated from that list so that a key is written down once; see case_keys.h for the typed
/// view (config::case_keys()).
struct CaseConfig {
#define CAPSIM_CASE_KEY(type, field, name, default_value, ...) type field = default_value;
#include "solver/config/case_keys.def"
#undef CAPSIM_CASE_KEY

  /// @brief Throws ConfigError naming the first key whose value the registry does not accept.
  void validate() const;
  /// @brief The effective configuration as TOML text (every key, defaults included).
  [[nodiscard]] std::string to_toml() const;
  /// @brief Canonical key → value text of every parameter (for HDF5 attributes and identities).
  [[nodiscard]] std::map<std::string, std::string> to_map() const;
};

/// @brief Every accepted case key as "section.key", in file order (the names of config::case_keys()).
std::vector<std::string> case_key_names();

/// @brief Read a case file (may be empty: all defaults) and apply `section.key=value` overrides.
/// @throws ConfigError for a missing/unreadable/unparsable file, an unknown key, a wrong type or a value
/// out of range; the message names the key or file.
CaseConfig load_case_config(const std::string& path, const std::vector<std::string>& overrides);

/// @brief Parse a case from TOML text (same rules as load_case_config; `origin` names it in messages).
CaseConfig parse_case_config(const std::string& toml_text, const std::string& origin,
                             const std::vector<std::string>& overrides = {});

}  // namespace capsim::config
