// What a path is when it should be a regular file, told from its status alone.
#pragma once

#include <filesystem>
#include <string>

namespace crater {

/// For a path that exists but is not a regular file (symbolic links followed): what it is,
/// "is a directory", "is a FIFO (named pipe)", ...; empty for a regular file and for a path
/// whose status cannot be read (opening it then reports the error). Nothing is opened, so a
/// FIFO cannot block and a device cannot stream forever.
inline std::string not_a_regular_file(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  switch (fs::status(path, ec).type()) {
    case fs::file_type::directory:
      return "is a directory";
    case fs::file_type::character:
      return "is a character device";
    case fs::file_type::block:
      return "is a block device";
    case fs::file_type::fifo:
      return "is a FIFO (named pipe)";
    case fs::file_type::socket:
      return "is a socket";
    case fs::file_type::regular:
    case fs::file_type::not_found:
    case fs::file_type::none:
      return {};
    default:
      return "is not a regular file";
  }
}

}  // namespace crater
