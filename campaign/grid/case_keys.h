#pragma once
/// @file
/// @brief The case keys as the campaign sees them: the solver's key registry (solver/config/case_keys.h,
/// entries in case_keys.def) under the campaign's names, plus what only the campaign has: the TOML text of
/// a value in a case file and the short grid-axis aliases.

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "solver/config/case_keys.h"

namespace capsim::campaign {

/// @brief A case-key value: integer, floating point, string or boolean.
using Value = config::KeyValue;
/// @brief The type a case key accepts.
using KeyType = config::KeyType;
/// @brief One registry entry (name, type, default_value, rule, in_identity, always_stored, doc).
using CaseKey = config::CaseKey;

// The registry's functions under the campaign's names (the same functions, so that calls found by
// argument-dependent lookup are not ambiguous): case_keys(), find_case_key(name) and
// check_case_value(key, value) ("" if the value has the key's type and lies in its range, else a message).
using config::case_keys;
using config::check_case_value;
using config::find_case_key;

/// @brief Text of a value as it appears in a campaign's case files (strings quoted and escaped, doubles in
/// their shortest round-trip decimal).
std::string value_to_text(const Value& v);

/// @brief The grid-axis aliases, "alias -> dotted key", in the order messages list them.
const std::vector<std::pair<std::string, std::string>>& axis_aliases();

/// @brief Short grid-axis aliases: capillary_number, aspect_ratio, law, skalak_C, mesh_level.
/// Returns the dotted key for an alias or a dotted key, or "" if unknown.
std::string resolve_axis_name(const std::string& name);

}  // namespace capsim::campaign
