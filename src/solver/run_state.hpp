// The time loop's own state (what a checkpoint holds besides the parts and the outputs), the
// guards a run is held to before it starts (output cadence, step count) and while it runs
// (the energy guard), and checkpoints: writing them, and continuing from one.
#pragma once

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "io/checkpoint/checkpoint.hpp"
#include "io/output/run_directory.hpp"
#include "io/scenario/config.hpp"
#include "parts/state_archive.hpp"
#include "solver/energy_balance.hpp"
#include "solver/probes.hpp"
#include "solver/run_outputs.hpp"
#include "solver/simulation.hpp"

namespace crater::solver {
namespace fs = std::filesystem;

// The time loop's own state: what a checkpoint holds besides the parts and the outputs.
struct LoopState {
  Real t = 0;
  Index steps = 0;
  Index frame = 1;
  Real next_frame_t = 0;
  Real dt_min = std::numeric_limits<Real>::infinity(), dt_max = 0, dt = 0;
  Energies e0;
  EnergyTrack track;
  Real err = 0;
  std::vector<Real> part_total0_j;  // each part's total energy at t = 0 (the energy guard)
  std::uint8_t energy_warned = 0;   // the guard's warning was given
  // Multi-rate stepping (multi_rate.hpp): the plan of the next cycle (each part's step in base
  // steps, and the base step), decided at the end of the last one, and the steps each part has
  // taken; empty otherwise.
  std::vector<std::int64_t> rate_ratio;
  Real rate_base_step_s = 0;
  std::vector<std::int64_t> part_steps;
  std::vector<Real> rate_carried;  // MultiRate::carried(), set when a checkpoint is written

  void save(parts::StateWriter& w) const {
    w.tag("loop");
    w.value(t);
    w.value(steps);
    w.value(frame);
    w.value(next_frame_t);
    w.value(dt_min);
    w.value(dt_max);
    w.value(dt);
    w.value(e0);
    w.value(track);
    w.value(err);
    w.vector(part_total0_j);
    w.value(energy_warned);
    w.vector(rate_ratio);
    w.value(rate_base_step_s);
    w.vector(part_steps);
    w.vector(rate_carried);
  }
  void load(parts::StateReader& r) {
    r.tag("loop");
    r.value(t);
    r.value(steps);
    r.value(frame);
    r.value(next_frame_t);
    r.value(dt_min);
    r.value(dt_max);
    r.value(dt);
    r.value(e0);
    r.value(track);
    r.value(err);
    r.vector(part_total0_j);
    r.value(energy_warned);
    r.vector(rate_ratio);
    r.value(rate_base_step_s);
    r.vector(part_steps);
    r.vector(rate_carried);
  }
};

// The energy guard (time.energy_warn_error, time.energy_stop_error), checked where a history
// row is computed: a balance error above the stop level ends the run as a numerical failure
// naming the part whose total energy grew most since t = 0.
template <int D>
void guard_energy(const io::Config& c, LoopState& st, const std::vector<Energies>& per,
                  const std::vector<std::unique_ptr<Part<D>>>& parts) {
  const Real err = std::abs(st.err);
  const Real warn = c.time.energy_warn_error, stop = c.time.energy_stop_error;
  if (!(stop > 0 && err > stop) && !(warn > 0 && err > warn && !st.energy_warned)) return;
  std::size_t grew = 0;
  Real most = -std::numeric_limits<Real>::infinity();
  for (std::size_t k = 0; k < per.size() && k < st.part_total0_j.size(); ++k) {
    const Real gain = total_energy(per[k]) - st.part_total0_j[k];
    if (gain > most) most = gain, grew = k;
  }
  const std::string who =
      parts.empty() ? std::string("?") : fmt::format("'{}'", parts[grew]->name());
  const std::string what =
      fmt::format("the energy balance error is {:.3g} % at step {} (part {} gained most: {:.4g} J)",
                  100 * st.err, st.steps, who, most);
  if (stop > 0 && err > stop)
    throw NumericalError(parts.empty() ? "?" : parts[grew]->name(), -1, st.t,
                         what + fmt::format(", above time.energy_stop_error = {:.3g} %; lower "
                                            "time.safety_factor, check the part's settings, or "
                                            "raise the limit (0: off)",
                                            100 * stop));
  spdlog::warn("{}, above time.energy_warn_error = {:.3g} % (warned once; the run goes on)", what,
               100 * warn);
  st.energy_warned = 1;
}

// VTU bytes of one frame of every part (points, connectivity, fields), as written appended.
template <int D>
double frame_bytes(const std::vector<std::unique_ptr<Part<D>>>& parts) {
  double bytes = 0;
  for (const auto& p : parts) {
    const Geometry<D> g = p->geometry();
    const double points = g.points ? static_cast<double>(g.points->size()) : 0.0;
    bytes += points * 3 * sizeof(Real) + 2048;
    bytes += static_cast<double>(g.connectivity.size() + g.offsets.size()) * 8 +
             static_cast<double>(g.cell_types.size());
    if (g.connectivity.empty()) bytes += points * 17;  // vertex cells
    for (const auto& v : p->point_fields())
      bytes += static_cast<double>(v.size) * v.components * 8;
    for (const auto& v : p->cell_fields())
      bytes += static_cast<double>(v.size) * v.components * 8;
  }
  return bytes;
}

// Output cadence: the frames' bytes within output.max_bytes and the disk's free space, and a
// warning when frames come faster than the stable step (each step then lands on a frame and
// is shortened to it). Returns the warnings.
template <int D>
std::vector<std::string> check_output_cadence(const io::Config& c,
                                              const std::vector<std::unique_ptr<Part<D>>>& parts,
                                              Real stable_step_s, const fs::path& out_dir) {
  std::vector<std::string> warnings;
  if (!c.output.vtu) return warnings;
  double frames = std::ceil(c.end_time_s / c.output.interval_s) + 1;
  if (c.time.max_steps > 0) frames = std::min(frames, static_cast<double>(c.time.max_steps) + 1);
  const double per_frame = frame_bytes(parts);
  const double bytes = frames * per_frame;
  if (bytes > c.output.max_bytes)
    throw InputError(c.output.interval_where, "output.interval_s",
                     fmt::format("frames of at most output.max_bytes = {:.3g} GB in all; {:.0f} "
                                 "frames of {:.3g} MB each would take {:.3g} GB (raise "
                                 "interval_s, set output.vtu = false, or raise max_bytes)",
                                 c.output.max_bytes / 1e9, frames, per_frame / 1e6, bytes / 1e9));
  std::error_code ec;
  fs::path probe = out_dir.empty() ? fs::current_path(ec) : out_dir;
  while (!probe.empty() && !fs::exists(probe, ec) && probe.has_parent_path() &&
         probe != probe.parent_path())
    probe = probe.parent_path();
  const auto space = fs::space(probe.empty() ? fs::path(".") : probe, ec);
  if (!ec && bytes > static_cast<double>(space.available))
    warnings.push_back(
        fmt::format("the VTU frames will take about {:.3g} GB and {} has {:.3g} "
                    "GB free",
                    bytes / 1e9, probe.string(), static_cast<double>(space.available) / 1e9));
  if (c.output.interval_s < stable_step_s)
    warnings.push_back(fmt::format(
        "output.interval_s = {:.4g} s is below the stable step {:.4g} s: every step ends on a "
        "frame and is shortened to the interval ({:.3g} times as many steps)",
        c.output.interval_s, stable_step_s, stable_step_s / c.output.interval_s));
  return warnings;
}

// A run of more steps than any machine takes (end_time_s / step above 1e10, and no
// time.max_steps) is a mistake in the end time or the step, refused before any work.
void check_step_count(const io::Config& c, Real step_s);

template <int D>
// On ranks every rank calls it (the parts gather their state, Part::save_state), and the root
// alone, the one with a manifest, writes the file.
void write_checkpoint(const io::Config& c, io::RunManifest* writer, const LoopState& st,
                      const Outputs<D>& out, const std::vector<std::unique_ptr<Part<D>>>& parts,
                      const Probes<D>& probes) {
  // Every rank saves (the parts gather their state to rank 0 inside save_state); only the rank
  // that writes the run directory keeps the bytes, passing them to the file as they come.
  const auto save = [&](parts::StateWriter& w) {
    st.save(w);
    out.save(w);
    w.tag("parts");
    w.value(static_cast<std::uint64_t>(parts.size()));
    for (const auto& p : parts) {
      w.tag(p->name());
      p->save_state(w);
    }
    probes.save(w);
  };
  if (!writer) {
    parts::StateWriter discard([](std::string_view) {});
    save(discard);
    return;
  }
  io::RunManifest& manifest = *writer;
  manifest.record("checkpoints/");
  const fs::path cdir = manifest.dir() / "checkpoints";
  fs::create_directories(cdir);
  io::CheckpointFile file(cdir / fmt::format("step_{:012d}.ckpt", st.steps),
                          {D, c.state_hash, static_cast<std::int64_t>(st.steps), st.t});
  save(file.writer());
  file.commit();
  // Keep the newest checkpoint_keep files.
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(cdir)) {
    if (e.path().extension() == ".ckpt") files.push_back(e.path());
    // A checkpoint's temporary file is left behind only by a run killed while writing it.
    if (e.path().extension() == ".tmp") fs::remove(e.path());
  }
  std::sort(files.begin(), files.end());
  const auto keep = static_cast<std::size_t>(std::max<Index>(c.output.checkpoint_keep, 1));
  for (std::size_t k = 0; k + keep < files.size(); ++k)
    fs::remove(files[k]);
}

// The run directory a checkpoint belongs to: <dir>/checkpoints/<file>.
fs::path run_dir_of_checkpoint(const fs::path& checkpoint);

bool same_directory(const fs::path& a, const fs::path& b);

// A run continued into another directory (--restart FILE --out DIR): the frames written
// before the checkpoint are linked (or copied) there, so that the PVD files list them; a
// frame that is missing is dropped from its collection with a warning.
void carry_frames(const fs::path& from, io::RunManifest& manifest,
                  std::vector<std::vector<std::pair<Real, std::string>>>& pvd);

// A row file (history.csv, gauges.csv) as the checkpoint saw it (its first `bytes` bytes), from
// the run directory the checkpoint belongs to. When that is another directory and the file is
// gone, the new one starts at the checkpoint's step (a warning says so).
std::string rows_at_checkpoint(const RunOptions& opt, const fs::path& from, const char* name,
                               std::uint64_t bytes, bool same_dir);

}  // namespace crater::solver
