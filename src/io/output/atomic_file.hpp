// Files written as a whole or not at all: data go to "<name>.tmp", are flushed and fsync'd,
// then renamed over the target. A reader (ParaView, a test, a resumed run) never sees half a
// file, and a full disk leaves the previous version in place.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>

namespace crater::io {

/// Writes `data` to `path` atomically. Throws std::runtime_error naming the path on failure.
void write_file_atomic(const std::filesystem::path& path, std::string_view data);

/// A file written piece by piece and made visible whole (checkpoints, which are written as the
/// state is produced rather than held twice in memory). Until commit() the data are in
/// "<name>.tmp"; an object destroyed uncommitted (an exception) removes it. Throws
/// std::runtime_error naming the path on failure.
class AtomicFile {
 public:
  explicit AtomicFile(const std::filesystem::path& path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  /// Appends.
  void write(std::string_view data);
  /// Overwrites bytes already written, from `offset` (a header filled in at the end).
  void write_at(std::uint64_t offset, std::string_view data);
  /// fsync, close, rename over the target.
  void commit();

 private:
  [[noreturn]] void fail(const char* what);
  std::filesystem::path path_, tmp_;
  int fd_ = -1;
};

/// Appends to a text file (history.csv); flushed after each call.
class AppendFile {
 public:
  AppendFile() = default;
  explicit AppendFile(const std::filesystem::path& path);
  ~AppendFile();
  AppendFile(const AppendFile&) = delete;
  AppendFile& operator=(const AppendFile&) = delete;
  void write(std::string_view s);
  void flush();

 private:
  std::FILE* f_ = nullptr;
  std::filesystem::path path_;
};

}  // namespace crater::io
