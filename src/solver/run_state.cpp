// The run's guards and continuing from a checkpoint; see run_state.hpp.
#include "solver/run_state.hpp"

#include <fstream>

namespace crater::solver {

void check_step_count(const io::Config& c, Real step_s) {
  constexpr double kMaxSteps = 1e10;
  const Real dt = c.time.fixed_dt_s ? *c.time.fixed_dt_s : step_s;
  if (c.time.max_steps > 0 || !(dt > 0)) return;
  const double steps = c.end_time_s / dt;
  if (steps > kMaxSteps)
    throw InputError(c.time.fixed_dt_s ? c.time.fixed_dt_where : SourceLocation{c.file, 0, 0},
                     "scenario.end_time_s",
                     fmt::format("a run of at most {:.0e} steps; end_time_s = {:.4g} s at a step "
                                 "of {:.4g} s takes {:.3g} (shorten end_time_s, or set "
                                 "time.max_steps to run a part of it)",
                                 kMaxSteps, c.end_time_s, dt, steps));
}

fs::path run_dir_of_checkpoint(const fs::path& checkpoint) {
  return checkpoint.parent_path().parent_path();
}

bool same_directory(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  const bool same = fs::equivalent(a.empty() ? "." : a, b.empty() ? "." : b, ec);
  return !ec && same;
}

namespace {

// `file` of the run in `from` linked (or copied) into the manifest's directory.
bool carry_file(const fs::path& from, io::RunManifest& manifest, const std::string& file) {
  std::error_code ec;
  const fs::path src = from / file, dst = manifest.dir() / file;
  fs::remove(dst, ec);
  fs::create_hard_link(src, dst, ec);
  if (ec) fs::copy_file(src, dst, fs::copy_options::overwrite_existing, ec);
  if (ec) {
    spdlog::warn("frame {} of the checkpoint's run is not carried over: {}", src.string(),
                 ec.message());
    return false;
  }
  return true;
}

// The pieces of a frame written by ranks (<part>_<tag>.pvtu: pieces/<part>_<tag>_<rank>.vtu).
bool carry_pieces(const fs::path& from, io::RunManifest& manifest, const std::string& pvtu) {
  const std::string stem = fs::path(pvtu).stem().string() + "_";
  std::error_code ec;
  fs::create_directories(manifest.dir() / "pieces", ec);
  manifest.record("pieces/");
  bool all = true;
  for (const auto& entry : fs::directory_iterator(from / "pieces", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(stem, 0) == 0 && entry.path().extension() == ".vtu")
      all = carry_file(from, manifest, "pieces/" + name) && all;
  }
  return all && !ec;
}

}  // namespace

void carry_frames(const fs::path& from, io::RunManifest& manifest,
                  std::vector<std::vector<std::pair<Real, std::string>>>& pvd) {
  for (auto& entries : pvd) {
    std::vector<std::pair<Real, std::string>> kept;
    for (auto& [t, file] : entries) {
      manifest.record(file);
      if (!carry_file(from, manifest, file)) continue;
      if (fs::path(file).extension() == ".pvtu" && !carry_pieces(from, manifest, file)) continue;
      kept.emplace_back(t, std::move(file));
    }
    entries = std::move(kept);
  }
}

std::string rows_at_checkpoint(const RunOptions& opt, const fs::path& from, const char* name,
                               std::uint64_t bytes, bool same_dir) {
  std::string rows;
  std::error_code ec;
  if (fs::exists(from / name, ec)) {
    // Only what the checkpoint saw is read (the file may have grown long since).
    io::require_own_file(from / name, same_dir ? "--resume" : "--restart",
                         std::numeric_limits<std::uintmax_t>::max());
    std::ifstream in(from / name, std::ios::binary);
    rows.resize(static_cast<std::size_t>(bytes));
    in.read(rows.data(), static_cast<std::streamsize>(bytes));
    rows.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  }
  if (rows.size() == bytes) return rows;
  if (same_dir || rows.size() > 0)
    throw InputError({(from / name).string(), 0, 0}, same_dir ? "--resume" : "--restart",
                     fmt::format("the run's {} as the checkpoint saw it ({} bytes); it has {} "
                                 "(continue into the directory the run wrote, or from a "
                                 "checkpoint of this run)",
                                 name, bytes, rows.size()));
  spdlog::warn("{} has no {}: {} starts its rows at the checkpoint's step", from.string(), name,
               (opt.out_dir / name).string());
  return {};
}

}  // namespace crater::solver
