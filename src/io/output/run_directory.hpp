// The run directory and its manifest: crater-manifest.txt lists, one relative name a line,
// every file crater wrote there (and the folders it owns: "checkpoints/", "report/"), in the
// order first written. `--force` removes what the manifest lists and nothing else, so a
// user's own files in the directory survive; a non-empty directory without a manifest is
// not crater's and is refused.
//
// The command file (crater-command.toml) records how the run was started (scenario, level,
// --set overrides, threads), so that `crater run --resume DIR` needs nothing retyped.
#pragma once

#include <filesystem>
#include <set>
#include <string>
#include <vector>

namespace crater::io {

inline constexpr const char* kManifestName = "crater-manifest.txt";
inline constexpr const char* kCommandName = "crater-command.toml";

/// Makes `dir` ready for a new run: creates it when missing; a directory holding anything
/// must hold a manifest (else InputError, key `--out`) and `force` must be set (else
/// InputError); then every file and folder the manifest lists, checkpoints/, report/ and the
/// manifest itself are removed. Files the manifest does not list are left alone.
void prepare_new_run_directory(const std::filesystem::path& dir, bool force);

/// The manifest of one run directory, appended to as files are written.
class RunManifest {
 public:
  /// Opens the manifest of `dir` (created when missing), reading the names it already holds.
  explicit RunManifest(std::filesystem::path dir);
  /// Records `relative_name` (a file, or a folder ending in '/') once; later calls with the
  /// same name do nothing. Throws std::runtime_error when the manifest cannot be written.
  void record(const std::string& relative_name);
  bool contains(const std::string& relative_name) const { return names_.count(relative_name); }
  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
  std::set<std::string> names_;
};

/// Refuses (InputError naming `key`) a file of crater's own that is not a regular file or is
/// larger than `max_bytes`: read back, it must neither block nor exhaust memory.
void require_own_file(const std::filesystem::path& path, const char* key, std::uintmax_t max_bytes);

/// The names a manifest lists that are safe to act on: relative, inside the directory (no
/// "..", no absolute path), in file order. Unsafe lines are skipped.
std::vector<std::string> read_manifest(const std::filesystem::path& dir);

/// How a run was started: written to crater-command.toml and summary.json.
struct RunCommand {
  std::string scenario;           // as given (a path or a bundled name)
  std::string scenario_file;      // the file it resolved to
  std::string level;              // --level, empty when none
  std::vector<std::string> sets;  // --set overrides, in order
  int threads = 0;                // --threads (0: not given)
  std::vector<std::string> argv;  // the whole command line
};

void write_run_command(const std::filesystem::path& dir, const RunCommand& command);
/// The command recorded in `dir`; InputError when it is missing or damaged.
RunCommand read_run_command(const std::filesystem::path& dir);

}  // namespace crater::io
