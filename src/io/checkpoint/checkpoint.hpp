// Checkpoints: the complete state of a run, so that a run resumed from one continues bit for
// bit as if it had never stopped (DESIGN §1, docs/theory.md "Checkpoints").
//
// File: one text line
//   crater checkpoint v3 dim=D scenario=<hash> step=N time=<hex float> bytes=B checksum=<hex>
// then B bytes of payload: tagged blocks written by StateWriter (the loop's counters, the
// output writers' state, each part's state in order). The checksum is FNV-1a 64 of the payload.
// Files are written atomically (temporary file, fsync, rename) and as the state is produced:
// the header line is written first with B as 20 zero-padded digits and filled in at the end,
// so the payload is never held in memory whole. A file that is damaged, of
// another format version or dimension, or of another scenario (its state hash after defaults
// and --set: Config::state_hash, which leaves out the keys a continued run may change, such as
// the end time) is refused with an InputError naming the file and the reason; nothing is run
// then.
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "io/output/atomic_file.hpp"
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

/// A checkpoint file being written: the payload through writer(), then commit() fills in the
/// header and makes the file visible. Destroyed uncommitted, it leaves nothing behind.
class CheckpointFile {
 public:
  CheckpointFile(const std::filesystem::path& path, const CheckpointHeader& header);
  ~CheckpointFile();
  CheckpointFile(const CheckpointFile&) = delete;
  CheckpointFile& operator=(const CheckpointFile&) = delete;
  StateWriter& writer() { return writer_; }
  void commit();

 private:
  std::unique_ptr<AtomicFile> file_;
  CheckpointHeader header_;
  StateWriter writer_;
};

/// Reads and verifies a checkpoint (format, size, checksum). Throws InputError naming the file
/// and what is wrong. The payload is returned in `payload`.
CheckpointHeader read_checkpoint(const std::filesystem::path& path, std::string& payload);

/// The newest checkpoint of a run directory that reads back intact (damaged ones are skipped
/// with a warning). Throws InputError if there is none.
std::filesystem::path newest_checkpoint(const std::filesystem::path& run_dir);

}  // namespace crater::io
