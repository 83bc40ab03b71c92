// Checkpoints: the complete state of a run, so that a run resumed from one continues bit for
// bit as if it had never stopped (DESIGN §1, docs/theory.md "Checkpoints").
//
// File: one text line
//   crater checkpoint v3 dim=D scenario=<hash> step=N time=<hex float> bytes=B checksum=<hex>
// then B bytes of payload: tagged blocks written by StateWriter (the loop's counters, the
// output writers' state, each part's state in order). The checksum is FNV-1a 64 of the payload.
// Files are written atomically (temporary file, fsync, rename). A file that is damaged, of
// another format version or dimension, or of another scenario (its state hash after defaults
// and --set: Config::state_hash, which leaves out the keys a continued run may change, such as
// the end time) is refused with an InputError naming the file and the reason; nothing is run
// then.
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "parts/state_archive.hpp"

namespace crater::io {

// The state archive's classes, as the checkpoint code names them.
using parts::StateReader;
using parts::StateWriter;

struct CheckpointHeader {
  int dimension = 0;
  std::string scenario_hash;  // Config::state_hash of the run that wrote it
  std::int64_t step = 0;
  Real time_s = 0;
};

/// Writes header + payload atomically.
void write_checkpoint(const std::filesystem::path& path, const CheckpointHeader& header,
                      const std::string& payload);

/// Reads and verifies a checkpoint (format, size, checksum). Throws InputError naming the file
/// and what is wrong. The payload is returned in `payload`.
CheckpointHeader read_checkpoint(const std::filesystem::path& path, std::string& payload);

/// The newest checkpoint of a run directory that reads back intact (damaged ones are skipped
/// with a warning). Throws InputError if there is none.
std::filesystem::path newest_checkpoint(const std::filesystem::path& run_dir);

}  // namespace crater::io
