// The file cache of settled DEM packings ([parts.packing] cache_dir): a settled packing is kept
// as <cache_dir>/<part>-<key>.pack, the key a hash of everything that shapes it
// (dem::packing_key_text), and reused by every later run with the same key.
//
// File: one header line (magic, key, dimension, count, checksum of the payload), then raw
// little-endian doubles, (x, r) per grain.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "dem/packing.hpp"

namespace crater::solver {

/// Writes the packing file at `path` (atomically: a reader sees the old file or the new one).
template <int D>
void save_packing(const std::string& path, std::uint64_t key, const std::vector<dem::Grain<D>>& g);

/// The grains of a packing file, or nothing if it is missing, of another key or dimension, or
/// damaged (a cache miss, never an error).
template <int D>
std::optional<std::vector<dem::Grain<D>>> load_packing(const std::string& path, std::uint64_t key);

}  // namespace crater::solver
