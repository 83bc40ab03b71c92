// Files written as a whole or not at all: data go to "<name>.tmp", are flushed and fsync'd,
// then renamed over the target. A reader (ParaView, a test, a resumed run) never sees half a
// file, and a full disk leaves the previous version in place.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>

namespace crater::io {

/// Writes `data` to `path` atomically. Throws std::runtime_error naming the path on failure.
void write_file_atomic(const std::filesystem::path& path, std::string_view data);

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
