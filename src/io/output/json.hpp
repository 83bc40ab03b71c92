// A small JSON text builder for summary.json (no JSON library in the dependency list; output
// only). Numbers keep 17 significant digits; non-finite numbers become null.
#pragma once

#include <fmt/format.h>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

namespace crater::io {

class JsonWriter {
 public:
  JsonWriter& begin_object() { return open('{'); }
  JsonWriter& end_object() { return close('}'); }
  JsonWriter& begin_array() { return open('['); }
  JsonWriter& end_array() { return close(']'); }

  JsonWriter& key(std::string_view k) {
    comma();
    indent();
    out_ += quote(k) + ": ";
    after_key_ = true;
    return *this;
  }
  JsonWriter& value(double v) {
    return raw(std::isfinite(v) ? fmt::format("{:.17g}", v) : std::string("null"));
  }
  JsonWriter& value(std::int64_t v) { return raw(std::to_string(v)); }
  JsonWriter& value(int v) { return raw(std::to_string(v)); }
  JsonWriter& value(bool v) { return raw(v ? "true" : "false"); }
  JsonWriter& value(std::string_view s) { return raw(quote(s)); }
  JsonWriter& value(const char* s) { return raw(quote(s)); }

  template <class T>
  JsonWriter& field(std::string_view k, const T& v) {
    key(k);
    return value(v);
  }

  const std::string& str() const { return out_; }

  static std::string quote(std::string_view s) {
    std::string o = "\"";
    for (unsigned char c : s) {
      switch (c) {
        case '"':
          o += "\\\"";
          break;
        case '\\':
          o += "\\\\";
          break;
        case '\n':
          o += "\\n";
          break;
        case '\r':
          o += "\\r";
          break;
        case '\t':
          o += "\\t";
          break;
        default:
          if (c < 0x20)
            o += fmt::format("\\u{:04x}", c);
          else
            o += static_cast<char>(c);
      }
    }
    return o + "\"";
  }

 private:
  JsonWriter& open(char c) {
    if (!after_key_) {
      comma();
      indent();
    }
    after_key_ = false;
    out_ += c;
    ++depth_;
    first_ = true;
    return *this;
  }
  JsonWriter& close(char c) {
    --depth_;
    if (!first_) {
      out_ += '\n';
      indent();
    }
    out_ += c;
    first_ = false;
    if (depth_ == 0) out_ += '\n';
    return *this;
  }
  JsonWriter& raw(const std::string& s) {
    if (!after_key_) {
      comma();
      indent();
    }
    after_key_ = false;
    out_ += s;
    first_ = false;
    return *this;
  }
  void comma() {
    if (depth_ == 0) return;
    out_ += first_ ? "\n" : ",\n";
    first_ = false;
  }
  void indent() { out_.append(static_cast<std::size_t>(2 * depth_), ' '); }

  std::string out_;
  int depth_ = 0;
  bool first_ = true;
  bool after_key_ = false;
};

}  // namespace crater::io
