// The state archive: a part's state as tagged binary blocks (StateWriter), read back with
// every block's tag and size checked (StateReader). Checkpoints (io/checkpoint/) wrap the
// bytes in a file, the writer passing them on as they come (a sink) rather than holding them
// all; the parts write and read them through Part::save_state / load_state. The two classes offer
// the same calls (tag, value, vector, block), so a part can state its layout once, in a function
// templated on the archive, for both directions.
#pragma once

#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "core/hash.hpp"
#include "core/types.hpp"

namespace crater::parts {

class StateWriter {
 public:
  /// Receives the bytes in order (a checkpoint's file).
  using Sink = std::function<void(std::string_view)>;

  /// The bytes are kept in memory: bytes().
  StateWriter() = default;
  /// The bytes go to `sink` in pieces of about `buffer_bytes` (large arrays directly), so the
  /// state is never held twice; flush() passes on the rest.
  explicit StateWriter(Sink sink, std::size_t buffer_bytes = std::size_t{1} << 20)
      : sink_(std::move(sink)), buffer_bytes_(buffer_bytes) {}

  /// A named marker; the reader checks it, so a layout change is caught at its first block.
  void tag(std::string_view name) {
    value(static_cast<std::uint32_t>(name.size()));
    put(name);
  }
  template <class T>
  void value(const T& v) {
    put({reinterpret_cast<const char*>(&v), sizeof(T)});
  }
  template <class T>
  void vector(const std::vector<T>& v) {
    value(static_cast<std::uint64_t>(v.size()));
    if (!v.empty()) put({reinterpret_cast<const char*>(v.data()), sizeof(T) * v.size()});
  }
  void string(std::string_view s) {
    value(static_cast<std::uint64_t>(s.size()));
    put(s);
  }
  /// An object that writes itself: x.save(*this).
  template <class T>
  void block(const T& x) {
    x.save(*this);
  }
  void flush() {
    if (sink_ && !bytes_.empty()) sink_(bytes_);
    if (sink_) bytes_.clear();
  }
  /// Everything written, when there is no sink.
  const std::string& bytes() const { return bytes_; }
  /// The count and the FNV-1a 64 checksum of everything written.
  std::uint64_t size() const { return size_; }
  std::uint64_t checksum() const { return checksum_; }

 private:
  void put(std::string_view s) {
    size_ += s.size();
    checksum_ = fnv1a(s, checksum_);
    if (sink_ && bytes_.size() + s.size() > buffer_bytes_) {
      flush();
      if (s.size() >= buffer_bytes_) return sink_(s);
    }
    bytes_.append(s);
  }
  Sink sink_;
  std::size_t buffer_bytes_ = 0;
  std::string bytes_;
  std::uint64_t size_ = 0;
  std::uint64_t checksum_ = fnv1a({});
};

class StateReader {
 public:
  StateReader(std::string_view bytes, std::string source)
      : bytes_(bytes), source_(std::move(source)) {}

  void tag(std::string_view name) {
    const auto n = value<std::uint32_t>();
    const std::string_view got = take(n);
    if (got != name)
      fail("expected block '" + std::string(name) + "', found '" + std::string(got) +
           "' (written by another version of crater or for another scenario)");
  }
  template <class T>
  T value() {
    T v;
    std::memcpy(&v, take(sizeof(T)).data(), sizeof(T));
    return v;
  }
  template <class T>
  void value(T& v) {
    v = value<T>();
  }
  template <class T>
  void vector(std::vector<T>& v) {
    const auto n = value<std::uint64_t>();
    if (n > (bytes_.size() - pos_) / (sizeof(T) > 0 ? sizeof(T) : 1)) fail("truncated array");
    v.resize(static_cast<std::size_t>(n));
    if (n > 0) std::memcpy(static_cast<void*>(v.data()), take(sizeof(T) * n).data(), sizeof(T) * n);
  }
  std::string string() {
    const auto n = value<std::uint64_t>();
    return std::string(take(n));
  }
  /// An object that reads itself: x.load(*this).
  template <class T>
  void block(T& x) {
    x.load(*this);
  }
  bool done() const { return pos_ == bytes_.size(); }
  [[noreturn]] void fail(const std::string& why) const {
    throw InputError({source_, 0, 0}, "checkpoint", "a checkpoint crater can use; " + why);
  }

 private:
  std::string_view take(std::uint64_t n) {
    if (n > bytes_.size() - pos_) fail("the file ends early");
    const std::string_view s = bytes_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  std::string_view bytes_;
  std::size_t pos_ = 0;
  std::string source_;
};

}  // namespace crater::parts
