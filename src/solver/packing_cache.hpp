// The file cache of settled DEM packings ([parts.packing] cache_dir): a settled packing is kept
// as <cache_dir>/<part>-<key>.pack, the key a hash of everything that shapes it
// (dem::packing_key_text), and reused by every later run with the same key.
//
// File: one header line (magic, key, dimension, count, contact slots per grain, whether rolling
// moments follow, checksum of the payload), then raw little-endian data: (x, r) per grain as
// doubles, then the contact histories (dem::ContactHistory: partners as int64, tangential
// springs, rolling moments), so that a run starts from the settled state with its friction.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dem/packing.hpp"

namespace crater::solver {

/// Writes the packing file at `path` (atomically: a reader sees the old file or the new one).
template <int D>
void save_packing(const std::string& path, std::uint64_t key, const dem::SettledPacking<D>& s);

/// The grains and contacts of a packing file, or nothing if it is missing, of another key,
/// dimension or format, or damaged (a cache miss, never an error).
template <int D>
std::optional<dem::SettledPacking<D>> load_packing(const std::string& path, std::uint64_t key);

/// The same from the bytes of such a file (a packing rank 0 settled, sent to the other ranks).
template <int D>
std::optional<dem::SettledPacking<D>> packing_from_bytes(std::string_view bytes, std::uint64_t key);

}  // namespace crater::solver
