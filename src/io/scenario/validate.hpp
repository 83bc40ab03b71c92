// Checks a parsed TOML document against a TableSchema and fills in defaults, so that the
// Config builder reads only present, well-typed, in-range values.
#pragma once

#include <toml++/toml.h>
#include <algorithm>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/scenario/schema.hpp"

namespace crater::io {

/// All problems found in one file, reported together (exit 2).
class InputErrors : public InputError {
 public:
  /// `errors` must not be empty; they are reported in file-line order.
  explicit InputErrors(std::vector<InputError> errors)
      : InputError(sorted(errors).front()), all_(std::move(errors)) {}
  const std::vector<InputError>& all() const { return all_; }

 private:
  static std::vector<InputError>& sorted(std::vector<InputError>& e) {
    std::stable_sort(e.begin(), e.end(), [](const InputError& a, const InputError& b) {
      return a.where().line < b.where().line;
    });
    return e;
  }
  std::vector<InputError> all_;
};

/// Location of a node: its own source if it has one, else `fallback`.
SourceLocation where_of(const toml::node& node, const SourceLocation& fallback);

/// Validates `table` (the document root or a sub-table at `path`) against `schema`.
/// `dimension` sets the length of RealVector keys. Defaults are inserted into `table`.
/// Problems are appended to `errors`.
void validate_table(toml::table& table, const TableSchema& schema, const std::string& path,
                    int dimension, const SourceLocation& table_where,
                    std::vector<InputError>& errors);

}  // namespace crater::io
