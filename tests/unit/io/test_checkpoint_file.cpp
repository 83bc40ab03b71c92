// Unit tests of checkpoints written as the state is produced (src/io/checkpoint/checkpoint.hpp,
// src/parts/state_archive.hpp): a StateWriter with a sink passes on exactly the bytes it would
// have kept, with their count and FNV-1a checksum; a CheckpointFile reads back through
// read_checkpoint; one destroyed before commit() leaves no file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/hash.hpp"
#include "io/checkpoint/checkpoint.hpp"

namespace crater::io {
namespace {

namespace fs = std::filesystem;

// A layout with small values and arrays larger than the sink's buffer of 64 bytes.
template <class W>
void write_sample(W& w) {
  w.tag("sample");
  w.value(std::int64_t{42});
  w.vector(std::vector<double>{1.5, -2.25, 3.0});
  std::vector<std::int32_t> big(100);
  for (std::size_t i = 0; i < big.size(); ++i)
    big[i] = static_cast<std::int32_t>(i * i);
  w.vector(big);
  w.string("end of sample");
}

TEST(StateWriter, SinkReceivesTheSameBytesInPieces) {
  StateWriter kept;
  write_sample(kept);

  std::string received;
  int pieces = 0;
  StateWriter passed(
      [&](std::string_view s) {
        received.append(s);
        ++pieces;
      },
      64);
  write_sample(passed);
  EXPECT_LT(received.size(), kept.bytes().size());  // the last piece is still buffered
  passed.flush();
  EXPECT_EQ(received, kept.bytes());
  EXPECT_GT(pieces, 2);
  EXPECT_EQ(passed.size(), kept.bytes().size());
  EXPECT_EQ(passed.checksum(), fnv1a(kept.bytes()));
  EXPECT_EQ(kept.checksum(), fnv1a(kept.bytes()));
}

fs::path scratch_dir(const char* name) {
  const fs::path d = fs::temp_directory_path() / ("crater_unit_" + std::string(name));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(CheckpointFile, ReadsBackWithItsHeader) {
  const fs::path dir = scratch_dir("checkpoint_file");
  const fs::path path = dir / "step_000000000007.ckpt";
  const CheckpointHeader h{3, "0123456789abcdef", 7, 1.25e-4};
  {
    CheckpointFile f(path, h);
    write_sample(f.writer());
    EXPECT_FALSE(fs::exists(path));  // not visible before commit
    f.commit();
  }
  ASSERT_TRUE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
  std::string payload;
  const CheckpointHeader back = read_checkpoint(path, payload);
  EXPECT_EQ(back.dimension, 3);
  EXPECT_EQ(back.scenario_hash, h.scenario_hash);
  EXPECT_EQ(back.step, 7);
  EXPECT_EQ(back.time_s, h.time_s);
  StateWriter kept;
  write_sample(kept);
  EXPECT_EQ(payload, kept.bytes());

  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::string digits = std::to_string(kept.bytes().size());  // 20, zero-padded
  digits.insert(0, 20 - digits.size(), '0');
  EXPECT_NE(line.find(" bytes=" + digits + " "), std::string::npos) << line;
  fs::remove_all(dir);
}

TEST(CheckpointFile, UncommittedLeavesNothing) {
  const fs::path dir = scratch_dir("checkpoint_uncommitted");
  const fs::path path = dir / "step_000000000001.ckpt";
  {
    CheckpointFile f(path, {2, "feed", 1, 0.0});
    write_sample(f.writer());
  }
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace crater::io
