#pragma once
/// @file
/// @brief A TOML value read as a registry key's value: the one conversion used for case files, `--set`
/// overrides and campaign files, so that all three accept the same types.

#include <optional>
#include <string>

#include <toml++/toml.h>

#include "solver/config/case_keys.h"

namespace capsim::config {

/// @brief What a TOML node holds, for messages: "a string", "an integer", "a float", ...
std::string toml_type_name(const toml::node& node);

/// @brief @p node as a value of @p key's type (an integer is accepted, as a double, for a float key; the
/// string "auto" for a number-or-auto key), not yet checked against the key's range.
/// @return nullopt with @p why = "expected an integer, got a float" (etc.) for a wrong type.
std::optional<KeyValue> toml_to_key_value(const CaseKey& key, const toml::node& node, std::string& why);

}  // namespace capsim::config
