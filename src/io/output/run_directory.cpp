#include "io/output/run_directory.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "core/error.hpp"
#include "core/file_kind.hpp"
#include "io/output/atomic_file.hpp"

namespace crater::io {
namespace fs = std::filesystem;

// crater's own files in a run directory, read back: regular files of a sane size, or an
// InputError naming the file (a FIFO must not block, a device not stream forever).
void require_own_file(const fs::path& path, const char* key, std::uintmax_t max_bytes) {
  const SourceLocation where{path.string(), 0, 0};
  if (const std::string kind = not_a_regular_file(path); !kind.empty())
    throw InputError(where, key, "a file crater wrote; it " + kind);
  std::error_code ec;
  const auto bytes = fs::file_size(path, ec);
  if (!ec && bytes > max_bytes)
    throw InputError(
        where, key,
        fmt::format("a file crater wrote (at most {} bytes); it has {}", max_bytes, bytes));
}

namespace {

// A manifest line names something inside the directory: relative, without "..".
bool safe_name(const std::string& name) {
  if (name.empty() || name.front() == '/') return false;
  for (const auto& part : fs::path(name))
    if (part == "..") return false;
  return true;
}

}  // namespace

std::vector<std::string> read_manifest(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  if (!fs::exists(dir / kManifestName, ec)) return names;
  require_own_file(dir / kManifestName, "--out", std::uintmax_t{1} << 28);
  std::ifstream in(dir / kManifestName);
  for (std::string line; std::getline(in, line);)
    if (safe_name(line)) names.push_back(line);
  return names;
}

void prepare_new_run_directory(const fs::path& dir, bool force) {
  const SourceLocation where{dir.string(), 0, 0};
  std::error_code ec;
  const auto st = fs::status(dir, ec);
  if (fs::exists(st) && !fs::is_directory(st))
    throw InputError(where, "--out", "a directory for the run; this is a file");
  if (fs::exists(st) && !fs::is_empty(dir, ec)) {
    if (!fs::exists(dir / kManifestName, ec))
      throw InputError(
          where, "--out",
          fs::exists(dir / "summary.json", ec)
              ? "a directory crater can clear; this one holds a run of an older crater (no "
                "crater-manifest.txt lists what it wrote): remove it by hand or choose another "
                "--out"
              : "an empty directory or one crater ran in; this one holds files crater did not "
                "write (it has no crater-manifest.txt), and crater deletes nothing it did not "
                "write: choose another --out");
    if (!force)
      throw InputError(where, "--out",
                       "a new directory; this one holds a run: pass --force to replace it (only "
                       "the files crater wrote, listed in crater-manifest.txt, are removed) or "
                       "choose another --out");
    for (const auto& name : read_manifest(dir)) {
      if (name.back() == '/')
        fs::remove_all(dir / name, ec);
      else
        fs::remove(dir / name, ec);
    }
    fs::remove_all(dir / "checkpoints", ec);
    fs::remove_all(dir / "report", ec);
    fs::remove(dir / kManifestName, ec);
  }
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw InputError(where, "--out", "a directory crater can create: " + ec.message());
}

RunManifest::RunManifest(fs::path dir) : dir_(std::move(dir)) {
  for (auto& name : read_manifest(dir_))
    names_.insert(std::move(name));
}

void RunManifest::record(const std::string& relative_name) {
  if (!names_.insert(relative_name).second) return;
  const fs::path path = dir_ / kManifestName;
  std::FILE* f = std::fopen(path.c_str(), "a");
  const std::string line = relative_name + "\n";
  const bool ok = f && std::fwrite(line.data(), 1, line.size(), f) == line.size();
  const bool closed = f && std::fclose(f) == 0;
  if (!ok || !closed) {
    names_.erase(relative_name);
    throw std::runtime_error("cannot write " + path.string() + ": " + std::strerror(errno));
  }
}

void write_run_command(const fs::path& dir, const RunCommand& command) {
  toml::array sets, argv;
  for (const auto& s : command.sets)
    sets.push_back(s);
  for (const auto& a : command.argv)
    argv.push_back(a);
  toml::table t{{"scenario", command.scenario}, {"scenario_file", command.scenario_file},
                {"level", command.level},       {"set", std::move(sets)},
                {"threads", command.threads},   {"argv", std::move(argv)}};
  std::ostringstream text;
  text << "# How this run was started; `crater run --resume DIR` reads it.\n" << t << "\n";
  write_file_atomic(dir / kCommandName, text.str());
}

RunCommand read_run_command(const fs::path& dir) {
  const fs::path path = dir / kCommandName;
  const SourceLocation where{path.string(), 0, 0};
  std::error_code ec;
  if (!fs::exists(path, ec))
    throw InputError(where, "--resume",
                     "the run's command file, which crater writes when a run starts; it is "
                     "missing: name the scenario (crater run SCENARIO --resume DIR)");
  require_own_file(path, "--resume", std::uintmax_t{1} << 24);
  toml::table t;
  try {
    t = toml::parse_file(path.string());
  } catch (const toml::parse_error& e) {
    throw InputError({path.string(), static_cast<int>(e.source().begin.line), 0}, "--resume",
                     std::string("a readable command file: ") + std::string(e.description()));
  }
  RunCommand c;
  const auto* scenario = t["scenario"].as_string();
  if (!scenario) throw InputError(where, "scenario", "a string (the scenario the run used)");
  c.scenario = scenario->get();
  c.scenario_file = t["scenario_file"].value_or(std::string());
  c.level = t["level"].value_or(std::string());
  if (const auto* threads = t["threads"].node(); threads) {
    const auto* n = threads->as_integer();
    if (!n || n->get() < 0 || n->get() > 4096)
      throw InputError({path.string(), static_cast<int>(threads->source().begin.line), 0},
                       "threads", "an integer from 0 (all cores) to 4096");
    c.threads = static_cast<int>(n->get());
  }
  if (const auto* sets = t["set"].as_array())
    for (const auto& s : *sets)
      if (const auto* v = s.as_string()) c.sets.push_back(v->get());
  if (const auto* argv = t["argv"].as_array())
    for (const auto& a : *argv)
      if (const auto* v = a.as_string()) c.argv.push_back(v->get());
  return c;
}

}  // namespace crater::io
