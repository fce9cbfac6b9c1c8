#pragma once
/// @file
/// @brief The registry of case keys (`section.key`) a campaign may set, with types, defaults and checks.
/// It mirrors the solver's case file (schemas/campaign_keys.md documents both); keep them in sync.

#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace capsim::campaign {

/// @brief A case-key value: integer, floating point, string or boolean.
using Value = std::variant<std::int64_t, double, std::string, bool>;

/// @brief The type a case key accepts.
enum class KeyType { kFloat, kInt, kString, kBool, kFloatOrAuto };

/// @brief One documented case key.
struct CaseKey {
  std::string name;              ///< dotted name, e.g. "flow.capillary_number"
  KeyType type;                  ///< accepted type (integers are accepted for floats)
  std::optional<Value> fallback; ///< default filled into every case (none: only present when set)
  bool in_identity = true;       ///< false for keys that do not change results (output.*)
  std::string doc;               ///< one-line description with the allowed range
};

/// @brief All case keys known to the campaign manager.
const std::vector<CaseKey>& case_keys();

/// @brief The key named @p name, or nullptr.
const CaseKey* find_case_key(const std::string& name);

/// @brief Checks range/enumeration constraints of @p value for @p key; returns "" or a message.
std::string check_case_value(const CaseKey& key, const Value& value);

/// @brief Text of a value as it appears in TOML and identities (strings quoted).
std::string value_to_text(const Value& v);

/// @brief Short grid-axis aliases: capillary_number, aspect_ratio, law, skalak_C, mesh_level.
/// Returns the dotted key for an alias or a dotted key, or "" if unknown.
std::string resolve_axis_name(const std::string& name);

}  // namespace capsim::campaign
