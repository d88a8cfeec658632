// FNV-1a, 64 bits: a fingerprint of bytes (cache names, checkpoint keys and checksums). Not
// cryptographic: it tells files apart, it does not resist forgery.
#pragma once

#include <cstdint>
#include <string_view>

namespace kr {

inline uint64_t fnv1a(std::string_view bytes, uint64_t h = 0xcbf29ce484222325ull) {
    for (unsigned char c : bytes) h = (h ^ c) * 0x100000001b3ull;
    return h;
}

}  // namespace kr
