// Errors that leave the program with a defined exit code (DESIGN §1).
//   InputError     -> exit 2: the scenario, a mesh or a command-line value is wrong.
//   NumericalError -> exit 3: the run blew up (NaN, negative volume, lost particle).
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>

#include "core/types.hpp"

namespace crater {

inline constexpr int kExitOk = 0;
inline constexpr int kExitInput = 2;
inline constexpr int kExitNumerical = 3;
inline constexpr int kExitInterrupted = 130;

/// Where in the input an error sits. `line` is 0 when unknown (e.g. a missing key: then the
/// line of the enclosing table is given).
struct SourceLocation {
  std::string file;
  int line = 0;
  int column = 0;
};

/// A wrong input. The message names the file, line and key and says what was expected.
class InputError : public std::runtime_error {
 public:
  InputError(SourceLocation where, std::string key, std::string what_expected)
      : std::runtime_error(format(where, key, what_expected)),
        where_(std::move(where)),
        key_(std::move(key)) {}

  const SourceLocation& where() const { return where_; }
  const std::string& key() const { return key_; }

 private:
  static std::string format(const SourceLocation& where, const std::string& key,
                            const std::string& what) {
    // Appends one piece at a time (GCC 12 warns falsely on `s += "a" + std::string`).
    std::string s = where.file.empty() ? std::string("input") : where.file;
    if (where.line > 0) s.append(":").append(std::to_string(where.line));
    if (where.line > 0 && where.column > 0) s.append(":").append(std::to_string(where.column));
    s.append(": ");
    if (!key.empty()) s.append("key '").append(key).append("': ");
    s.append(what);
    return s;
  }

  SourceLocation where_;
  std::string key_;
};

/// A numerical failure inside the time loop, naming the part, the entity (none when
/// entity_id < 0: the part as a whole, e.g. its energy) and the time.
class NumericalError : public std::runtime_error {
 public:
  NumericalError(std::string part, Index entity_id, Real time_s, std::string what)
      : std::runtime_error("numerical failure in part '" + part + "'" +
                           (entity_id >= 0 ? ", entity " + std::to_string(entity_id) : "") +
                           ", t = " + to_string_s(time_s) + ": " + what),
        part_(std::move(part)),
        entity_id_(entity_id),
        time_s_(time_s) {}

  const std::string& part() const { return part_; }
  Index entity_id() const { return entity_id_; }
  Real time_s() const { return time_s_; }

 private:
  static std::string to_string_s(Real t) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9g s", t);
    return buf;
  }
  std::string part_;
  Index entity_id_;
  Real time_s_;
};

/// The run was stopped by SIGINT or SIGTERM after writing a checkpoint (exit 130).
class Interrupted : public std::runtime_error {
 public:
  Interrupted(int signal, Index step, Real time_s)
      : std::runtime_error("interrupted by signal " + std::to_string(signal) + " at step " +
                           std::to_string(step) + ", t = " + std::to_string(time_s) + " s"),
        signal_(signal) {}
  int signal() const { return signal_; }

 private:
  int signal_;
};

}  // namespace crater
