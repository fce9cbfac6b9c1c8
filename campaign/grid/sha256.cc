#include "campaign/grid/sha256.h"

#include <openssl/evp.h>

#include <array>
#include <stdexcept>

namespace capsim::campaign {

std::string sha256_hex(std::string_view data) {
  std::array<unsigned char, EVP_MAX_MD_SIZE> md{};
  unsigned int len = 0;
  // EVP_Digest is the one-shot form of EVP_DigestInit/Update/Final (it allocates and frees its context).
  if (EVP_Digest(data.data(), data.size(), md.data(), &len, EVP_sha256(), nullptr) != 1 || len != 32)
    throw std::runtime_error("sha256_hex: libcrypto EVP_Digest(SHA-256) failed");
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out(2 * len, '0');
  for (unsigned int i = 0; i < len; ++i) {
    out[2 * i] = kHex[md[i] >> 4];
    out[2 * i + 1] = kHex[md[i] & 0xf];
  }
  return out;
}

}  // namespace capsim::campaign
