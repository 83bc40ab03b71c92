// A declarative schema for scenario files: every key with its type, unit, default, range and
// documentation. The same tables validate input (io/scenario/validate.cpp) and generate
// docs/scenario-format.md (`crater schema --markdown`), so the two cannot drift apart.
#pragma once

#include <iterator>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace crater::io {

enum class KeyType {
  Real,         // floating point (integers are accepted and converted)
  Integer,      // integer
  Bool,         // true / false
  String,       // free text
  Choice,       // one of `choices`
  ChoiceList,   // array of distinct strings, each one of `choices`
  StringArray,  // array of distinct strings (names), any number
  RealVector,   // array of reals with `dimension` entries
  RealArray,    // array of reals of any length
  Table,        // sub-table described by `sub`
  TableArray,   // array of tables ([[name]]) each described by `sub`
};

/// What a key's type is called: in the scenario reference (`doc`, e.g. "number") and in an
/// error's "expected ..." (`expected`, e.g. "a number").
struct KeyTypeWords {
  const char* doc;
  const char* expected;
};
/// By KeyType, in its order.
inline constexpr KeyTypeWords kKeyTypeWords[] = {
    {"number", "a number"},
    {"integer", "an integer"},
    {"bool", "true or false"},
    {"string", "a string"},
    {"string", "a string"},
    {"array of strings", "an array of strings"},
    {"[string, ...]", "an array of strings"},
    {"[number; dimension]", "an array of numbers"},
    {"[number, ...]", "an array of numbers"},
    {"table", "a table"},
    {"array of tables", "an array of tables ([[...]])"}};
static_assert(std::size(kKeyTypeWords) == static_cast<std::size_t>(KeyType::TableArray) + 1);
inline KeyTypeWords words_of(KeyType t) {
  return kKeyTypeWords[static_cast<std::size_t>(t)];
}

struct TableSchema;

struct KeySchema {
  std::string name;
  KeyType type = KeyType::Real;
  std::string unit;       // SI unit, "1" for dimensionless, "" for non-numbers
  std::string doc;        // one or two sentences
  bool required = false;  // no default: must be given
  std::optional<std::string>
      default_toml;           // default as a TOML literal, e.g. "0.9", "\"wendland_c2\""
  std::optional<double> min;  // inclusive unless min_exclusive
  bool min_exclusive = false;
  std::optional<double> max;         // inclusive
  std::vector<std::string> choices;  // for Choice
  const TableSchema* sub = nullptr;  // for Table / TableArray
  // Table: when absent, it is created (so that its defaults apply) unless this is set; then
  // absence means "not given" (e.g. a material without [materials.damage]).
  bool absent_means_unset = false;
  // StringArray: the same string may appear more than once (e.g. one group for each of two
  // parts); otherwise each is listed once.
  bool repeats = false;
};

/// A table's keys. A table with a discriminator (e.g. `model` of a material) has common keys
/// plus the keys of the variant the discriminator selects.
struct TableSchema {
  std::string name;  // dotted path used in docs, e.g. "parts.sph"
  std::string doc;
  std::vector<KeySchema> keys;
  std::string discriminator;  // name of a Choice key among `keys`, or empty
  std::map<std::string, std::vector<KeySchema>> variants;
};

/// The root schema of a scenario file.
const TableSchema& scenario_schema();

/// parts.fem.hourglass_coefficient when unset, by form: the one default the schema cannot state
/// as a value of its own (it depends on parts.fem.hourglass).
inline constexpr double kHourglassViscousDefault = 0.1;
inline constexpr double kHourglassStiffnessDefault = 0.05;

/// Markdown reference of every key (docs/scenario-format.md is this text).
std::string schema_markdown();
// The same reference as plain text for a terminal (`crater schema`).
std::string schema_text();

}  // namespace crater::io
