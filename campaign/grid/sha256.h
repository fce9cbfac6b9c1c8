#pragma once
/// @file
/// @brief SHA-256 (FIPS 180-4) for case identities; small and dependency free.

#include <string>
#include <string_view>

namespace capsim::campaign {

/// @brief Lower-case hexadecimal SHA-256 digest (64 characters) of @p data.
std::string sha256_hex(std::string_view data);

}  // namespace capsim::campaign
