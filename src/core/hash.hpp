// 64-bit FNV-1a (Fowler, Noll, Vo): a fast, stable hash for cache keys and file checksums.
// Not cryptographic: it detects accidental damage and mismatched inputs, not tampering.
#pragma once

#include <cstdint>
#include <string_view>

namespace crater {

inline std::uint64_t fnv1a(std::string_view bytes, std::uint64_t h = 0xcbf29ce484222325ULL) {
  for (const unsigned char c : bytes) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

}  // namespace crater
