#include "io/output/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace crater::io {

void write_file_atomic(const std::filesystem::path& path, std::string_view data) {
  const std::filesystem::path tmp = path.string() + ".tmp";
  auto fail = [&](const char* what) {
    const std::string msg =
        std::string("cannot write ") + path.string() + ": " + what + ": " + std::strerror(errno);
    ::unlink(tmp.c_str());
    throw std::runtime_error(msg);
  };
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail("open");
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      ::close(fd);
      fail("write");
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    ::close(fd);
    fail("fsync");
  }
  if (::close(fd) != 0) fail("close");
  if (::rename(tmp.c_str(), path.c_str()) != 0) fail("rename");
}

AppendFile::AppendFile(const std::filesystem::path& path) : path_(path) {
  f_ = std::fopen(path.c_str(), "w");
  if (!f_) throw std::runtime_error("cannot open " + path.string() + ": " + std::strerror(errno));
}

AppendFile::~AppendFile() {
  if (f_) std::fclose(f_);
}

void AppendFile::write(std::string_view s) {
  if (!f_) return;
  if (std::fwrite(s.data(), 1, s.size(), f_) != s.size())
    throw std::runtime_error("cannot write " + path_.string() + ": " + std::strerror(errno));
}

void AppendFile::flush() {
  if (f_ && std::fflush(f_) != 0)
    throw std::runtime_error("cannot write " + path_.string() + ": " + std::strerror(errno));
}

}  // namespace crater::io
