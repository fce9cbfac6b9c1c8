#pragma once
/// @file
/// @brief SHA-256 (FIPS 180-4) of case identities, computed by OpenSSL's libcrypto (EVP digest API).

#include <string>
#include <string_view>

namespace capsim::campaign {

/// @brief Lower-case hexadecimal SHA-256 digest (64 characters) of @p data.
/// @throws std::runtime_error if libcrypto fails (out of memory); it never does for valid input.
std::string sha256_hex(std::string_view data);

}  // namespace capsim::campaign
