// Scenario loading: file (or bundled name) -> TOML -> overrides -> schema validation ->
// cross-checks -> immutable Config. Every problem is an InputError (exit 2).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "io/scenario/config.hpp"

namespace crater::io {

/// Directory of the bundled scenarios (next to the binary when installed, else the source tree).
std::filesystem::path bundled_scenario_dir();

/// Names of the bundled scenarios (file stems), sorted.
std::vector<std::string> bundled_scenarios();

/// A path to an existing file, or the name of a bundled scenario.
std::filesystem::path resolve_scenario(const std::string& path_or_name);

/// Loads and validates. `overrides` are "dotted.key=TOML value" strings from --set; `level`
/// names one of the file's [levels.<name>] (its overrides apply first), or is empty.
Config load_scenario(const std::string& path_or_name, const std::vector<std::string>& overrides,
                     const std::string& level = "");

/// Same, from text (tests, fuzzing). `source_name` is used in messages.
Config load_scenario_text(const std::string& text, const std::string& source_name,
                          const std::vector<std::string>& overrides, const std::string& level = "");

}  // namespace crater::io
