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

/// The bytes of a packing file; empty if it cannot be read.
std::string read_packing_file(const std::string& path);

/// The grains and contacts of a packing file's bytes, or nothing if they are of another key,
/// dimension or format, or damaged (a cache miss, never an error). Rank 0 sends the bytes of the
/// packing it used to the other ranks, which read them with this too.
template <int D>
std::optional<dem::SettledPacking<D>> packing_from_bytes(std::string_view bytes, std::uint64_t key);

}  // namespace crater::solver
