#include "solver/simulation.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <fstream>
#include <iterator>
#include <limits>

#include "contact/coupling.hpp"
#include "core/error.hpp"
#include "io/checkpoint/checkpoint.hpp"
#include "io/output/atomic_file.hpp"
#include "io/output/json.hpp"
#include "io/output/run_directory.hpp"
#include "io/output/vtu_writer.hpp"
#include "parallel/parallel.hpp"
#include "solver/assembly.hpp"
#include "solver/memory_estimate.hpp"
#include "solver/probes.hpp"
#include "solver/progress.hpp"

namespace crater::solver {
namespace fs = std::filesystem;

namespace {

template <int D>
struct StepLimit {
  Real dt_s = std::numeric_limits<Real>::infinity();       // the limit as its part states it
  Real allowed_s = std::numeric_limits<Real>::infinity();  // the step it allows (safety applied)
  std::string who;   // "part 'x'" or the contact; empty when nothing limits the step
  std::string part;  // the limiting part's name, or "contact"
  StableStep detail;
};

/// The limit that allows the smallest step under `safety_factor` (1: the limits as stated,
/// which a fixed step must respect).
template <int D>
StepLimit<D> smallest_stable_step(const std::vector<std::unique_ptr<Part<D>>>& parts,
                                  const contact::Coupling<D>* coupling, Real safety_factor) {
  StepLimit<D> lim;
  auto consider = [&](const StableStep& s, std::string who, std::string part) {
    if (s.allowed_s(safety_factor) < lim.allowed_s)
      lim = {s.dt_s, s.allowed_s(safety_factor), std::move(who), std::move(part), s};
  };
  for (const auto& p : parts)
    consider(p->stable_step(), "part '" + p->name() + "'", p->name());
  if (coupling && !coupling->empty())
    consider(coupling->stable_step(parts), "the contacts", "contact");
  return lim;
}

// The user's fixed step must not exceed the stable limit (READING-NOTES: the paper's 1 us
// does); the error names the limiting part.
template <int D>
void check_fixed_step(const io::Config& c, const StepLimit<D>& lim) {
  if (!c.time.fixed_dt_s || lim.who.empty()) return;
  if (*c.time.fixed_dt_s > lim.dt_s)
    throw InputError(c.time.fixed_dt_where, "time.fixed_dt_s",
                     fmt::format("fixed step {:.4g} s exceeds the stable limit {:.4g} s of {} "
                                 "({}, entity {}); use at most {:.4g} s or unset it",
                                 *c.time.fixed_dt_s, lim.dt_s, lim.who, lim.detail.reason,
                                 lim.detail.entity_id, lim.dt_s));
}

// ---- outputs -------------------------------------------------------------------------------

template <int D>
class Outputs {
 public:
  // A new run writes history.csv's header; a resumed one keeps the file's first
  // `resume_history` bytes (what it held at the checkpoint) and goes on from there.
  // `extra_columns` follow the energy columns (history_columns: contact forces, part totals).
  Outputs(const io::Config& c, io::RunManifest& manifest,
          const std::vector<std::unique_ptr<Part<D>>>& parts,
          const std::vector<std::string>& extra_columns, std::string history_prefix = {})
      : config_(c), manifest_(manifest), dir_(manifest.dir()), history_(open_history(manifest)) {
    for (const auto& p : parts) {
      manifest_.record(p->name() + ".pvd");
      pvd_.emplace_back(dir_ / (p->name() + ".pvd"));
    }
    if (history_prefix.empty()) {
      history_prefix =
          "step,time_s,dt_s,kinetic_j,internal_j,external_work_j,damping_j,hourglass_j,"
          "contact_j,eroded_j,total_j,energy_error";
      for (const auto& col : extra_columns)
        history_prefix += "," + col;
      history_prefix += "\n";
    }
    history_.write(history_prefix);
    history_bytes_ = history_prefix.size();
  }

  void save(parts::StateWriter& w) const {
    w.tag("outputs");
    w.value(static_cast<std::uint64_t>(history_bytes_));
    w.value(static_cast<std::uint64_t>(pvd_.size()));
    for (const auto& p : pvd_) {
      w.value(static_cast<std::uint64_t>(p.entries().size()));
      for (const auto& [t, f] : p.entries()) {
        w.value(t);
        w.string(f);
      }
    }
  }
  /// The PVD entries of a checkpoint; returns the length history.csv had then.
  static std::uint64_t load_pvd(parts::StateReader& r,
                                std::vector<std::vector<std::pair<Real, std::string>>>& pvd) {
    r.tag("outputs");
    const auto bytes = r.value<std::uint64_t>();
    pvd.resize(r.value<std::uint64_t>());
    for (auto& entries : pvd) {
      entries.resize(r.value<std::uint64_t>());
      for (auto& [t, f] : entries) {
        r.value(t);
        f = r.string();
      }
    }
    return bytes;
  }
  void restore_pvd(std::vector<std::vector<std::pair<Real, std::string>>> pvd) {
    for (std::size_t k = 0; k < pvd_.size() && k < pvd.size(); ++k)
      pvd_[k].restore(std::move(pvd[k]));
  }

  void frame(const std::vector<std::unique_ptr<Part<D>>>& parts, Real t, const std::string& tag) {
    if (!config_.output.vtu) return;
    for (std::size_t k = 0; k < parts.size(); ++k) {
      const std::string file = fmt::format("{}_{}.vtu", parts[k]->name(), tag);
      manifest_.record(file);
      write_part(*parts[k], dir_ / file, t);
      if (tag != "failure") pvd_[k].add(t, file);
    }
  }

  void write_part(const Part<D>& p, const fs::path& path, Real t) {
    const Geometry<D> g = p.geometry();
    io::VtuMesh mesh;
    mesh.num_points = static_cast<Index>(g.points->size());
    mesh.dimension = D;
    mesh.points = g.points->empty() ? nullptr : g.points->front().data();
    if (!g.connectivity.empty()) {
      mesh.connectivity = &g.connectivity;
      mesh.offsets = &g.offsets;
      mesh.cell_types = &g.cell_types;
    }
    auto arrays = [](const std::vector<fields::FieldView>& views) {
      std::vector<io::VtuArray> out;
      for (const auto& v : views)
        out.push_back(io::VtuArray{v.info->name, v.components, v.real_data, v.integer_data,
                                   v.components == D && D == 2});
      return out;
    };
    io::write_vtu(path, t, mesh, arrays(p.point_fields()), arrays(p.cell_fields()),
                  config_.output.vtu_encoding == io::VtuEncoding::Base64 ? io::VtuFormat::Base64
                                                                         : io::VtuFormat::Appended);
  }

  void history(Index step, Real t, Real dt, const Energies& e, Real total, Real error,
               const std::vector<Real>& extra) {
    std::string row = fmt::format(
        "{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},"
        "{:.17g},{:.17g},{:.17g}",
        step, t, dt, e.kinetic_j, e.internal_j, e.external_work_j, e.damping_j, e.hourglass_j,
        e.contact_j, e.eroded_j, total, error);
    for (Real v : extra)
      row += fmt::format(",{:.17g}", v);
    row += "\n";
    history_.write(row);
    history_bytes_ += row.size();
  }
  void flush() { history_.flush(); }
  io::RunManifest& manifest() { return manifest_; }

 private:
  static fs::path open_history(io::RunManifest& manifest) {
    manifest.record("history.csv");
    return manifest.dir() / "history.csv";
  }

  const io::Config& config_;
  io::RunManifest& manifest_;
  fs::path dir_;
  io::AppendFile history_;
  std::size_t history_bytes_ = 0;
  std::vector<io::PvdCollection> pvd_;
};

// Total energy: what the parts hold plus what left through damping, hourglass, contacts and
// erosion, minus the work done on them. Conserved up to discretisation error.
Real total_energy(const Energies& e) {
  return e.kinetic_j + e.internal_j + e.damping_j + e.hourglass_j + e.contact_j + e.eroded_j -
         e.external_work_j;
}

// The relative energy balance error: the drift of the total over the largest energy the run
// has held or been given, max over time of (kinetic + internal) and of the work done on it
// (LS-DYNA's energy ratio likewise divides by initial plus external work). The work matters for
// beds under gravity, whose kinetic and elastic energies stay small while gravity's work
// flows through them into dissipation.
struct EnergyTrack {
  Real initial_total = 0;
  Real scale = 0;  // the denominator of the relative error
  Real error(const Energies& e) {
    scale = std::max(
        {scale, std::abs(e.kinetic_j) + std::abs(e.internal_j), std::abs(e.external_work_j)});
    return scale > 0 ? (total_energy(e) - initial_total) / scale : 0.0;
  }
};

// Each part's energies, in part order, and their sum (the same additions in the same order).
template <int D>
std::vector<Energies> part_energies(const std::vector<std::unique_ptr<Part<D>>>& parts) {
  std::vector<Energies> per;
  per.reserve(parts.size());
  for (const auto& p : parts)
    per.push_back(p->energies());
  return per;
}
Energies sum_energies(const std::vector<Energies>& per) {
  Energies e;
  for (const Energies& x : per)
    e += x;
  return e;
}
template <int D>
Energies sum_energies(const std::vector<std::unique_ptr<Part<D>>>& parts) {
  return sum_energies(part_energies(parts));
}

// history.csv's columns after the energies: the contacts' forces, then (runs of several parts)
// each part's own total energy, energy_<part>_j, so that a drift can be traced to a part. The
// parts' totals add up to total_j.
template <int D>
std::vector<std::string> history_columns(const std::vector<std::unique_ptr<Part<D>>>& parts,
                                         const contact::Coupling<D>& coupling,
                                         const Probes<D>& probes) {
  std::vector<std::string> columns = coupling.history_columns();
  for (auto& col : probes.history_columns())
    columns.push_back(std::move(col));
  if (parts.size() > 1)
    for (const auto& p : parts)
      columns.push_back("energy_" + p->name() + "_j");
  return columns;
}
template <int D>
std::vector<Real> history_values(const std::vector<Energies>& per,
                                 const contact::Coupling<D>& coupling, Probes<D>& probes,
                                 const std::vector<std::unique_ptr<Part<D>>>& parts) {
  std::vector<Real> values = coupling.history_values();
  for (Real v : probes.history_values(parts))
    values.push_back(v);
  if (per.size() > 1)
    for (const Energies& e : per)
      values.push_back(total_energy(e));
  return values;
}

// summary.json's "run" block: how the run was started (crater-command.toml holds the same).
void write_command(io::JsonWriter& j, const io::RunCommand& command) {
  j.key("command").begin_object();
  j.field("scenario", command.scenario).field("level", command.level);
  j.key("set").begin_array();
  for (const auto& s : command.sets)
    j.value(s);
  j.end_array();
  j.field("threads", command.threads);
  j.key("argv").begin_array();
  for (const auto& a : command.argv)
    j.value(a);
  j.end_array();
  j.end_object();
}

/// What summary.json reports of the run besides the parts: its state and how it was started.
struct SummaryInputs {
  io::RunManifest& manifest;
  const io::RunCommand& command;
  const RunResult& r;
  Real dt_min, dt_max;
  const Energies& e0;
  const Energies& e;
  Real energy_error;
};

template <int D>
void write_summary(const io::Config& c, const SummaryInputs& in,
                   const std::vector<std::unique_ptr<Part<D>>>& parts, const std::string& status,
                   const std::string& message, const contact::Coupling<D>* coupling = nullptr,
                   const std::vector<Diagnostic>& metrics = {}) {
  const RunResult& r = in.r;
  const Real dt_min = in.dt_min, dt_max = in.dt_max;
  const Energies &e0 = in.e0, &e = in.e;
  const Real energy_error = in.energy_error;
  io::JsonWriter j;
  j.begin_object();
  j.field("crater_version", CRATER_VERSION);
  j.field("status", status);
  if (!message.empty()) j.field("message", message);
  j.key("scenario").begin_object();
  j.field("name", c.name).field("file", c.file).field("hash", c.hash);
  if (!c.level.empty()) j.field("level", c.level);
  j.field("dimension", c.dimension).field("end_time_s", c.end_time_s);
  j.end_object();
  j.key("parts").begin_array();
  for (const auto& p : parts) {
    j.begin_object();
    j.field("name", p->name()).field("method", p->method());
    j.field("count", static_cast<std::int64_t>(p->count())).field("mass_kg", p->mass_kg());
    const auto diags = p->diagnostics();
    if (!diags.empty()) {
      j.key("diagnostics").begin_object();
      for (const auto& d : diags)
        j.field(d.name, d.value);
      j.end_object();
    }
    j.end_object();
  }
  j.end_array();
  if (coupling && !coupling->empty()) {
    j.key("contacts").begin_object();
    for (const auto& d : coupling->diagnostics())
      j.field(d.name, d.value);
    j.end_object();
  }
  j.field("steps", static_cast<std::int64_t>(r.steps));
  j.field("time_s", r.time_s);
  j.key("time_step").begin_object();
  j.field("min_s", dt_min).field("max_s", dt_max).field("safety_factor", c.time.safety_factor);
  j.end_object();
  auto energies = [&](const char* name, const Energies& en) {
    j.key(name).begin_object();
    j.field("kinetic_j", en.kinetic_j).field("internal_j", en.internal_j);
    j.field("external_work_j", en.external_work_j).field("damping_j", en.damping_j);
    j.field("hourglass_j", en.hourglass_j).field("contact_j", en.contact_j);
    j.field("eroded_j", en.eroded_j).field("total_j", total_energy(en));
    j.end_object();
  };
  j.key("energy").begin_object();
  energies("initial", e0);
  energies("final", e);
  j.field("balance_error", energy_error);
  j.end_object();
  j.key("metrics").begin_object();
  for (const auto& m : metrics)
    j.field(m.name, m.value);
  j.end_object();
  // Everything above is identical for any thread count; this block is not.
  j.key("run").begin_object();
  j.field("wall_time_s", r.wall_s).field("threads", r.threads);
  // The time loop alone (no setup, no final output): what the peers' "Loop time" counts.
  j.field("loop_time_s", r.loop_s);
  // This process's steps over its own wall time (a resumed run counts from where it resumed).
  j.field("steps_per_s",
          r.wall_s > 0 ? static_cast<double>(r.steps - r.first_step) / r.wall_s : 0.0);
  if (r.first_step > 0) j.field("resumed_at_step", static_cast<double>(r.first_step));
  write_command(j, in.command);
  j.end_object();
  j.end_object();
  in.manifest.record("summary.json");
  io::write_file_atomic(in.manifest.dir() / "summary.json", j.str());
}

// SIGINT / SIGTERM: the loop finishes its step, writes a checkpoint and the outputs so far,
// and the program exits 130 (kExitInterrupted).
std::atomic<int> g_signal{0};
extern "C" void on_signal(int sig) {
  g_signal.store(sig);
}

struct SignalGuard {
  using Handler = void (*)(int);
  Handler old_int, old_term;
  SignalGuard() {
    g_signal.store(0);
    old_int = std::signal(SIGINT, on_signal);
    old_term = std::signal(SIGTERM, on_signal);
  }
  ~SignalGuard() {
    std::signal(SIGINT, old_int);
    std::signal(SIGTERM, old_term);
  }
};

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

template <int D>
void write_checkpoint(const io::Config& c, io::RunManifest& manifest, const LoopState& st,
                      const Outputs<D>& out, const std::vector<std::unique_ptr<Part<D>>>& parts,
                      const Probes<D>& probes) {
  parts::StateWriter w;
  st.save(w);
  out.save(w);
  w.tag("parts");
  w.value(static_cast<std::uint64_t>(parts.size()));
  for (const auto& p : parts) {
    w.tag(p->name());
    p->save_state(w);
  }
  probes.save(w);
  manifest.record("checkpoints/");
  const fs::path cdir = manifest.dir() / "checkpoints";
  fs::create_directories(cdir);
  io::write_checkpoint(cdir / fmt::format("step_{:012d}.ckpt", st.steps),
                       {D, c.hash, static_cast<std::int64_t>(st.steps), st.t}, w.bytes());
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
fs::path run_dir_of_checkpoint(const fs::path& checkpoint) {
  return checkpoint.parent_path().parent_path();
}

bool same_directory(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  const bool same = fs::equivalent(a.empty() ? "." : a, b.empty() ? "." : b, ec);
  return !ec && same;
}

// A run continued into another directory (--restart FILE --out DIR): the frames written
// before the checkpoint are linked (or copied) there, so that the PVD files list them; a
// frame that is missing is dropped from its collection with a warning.
void carry_frames(const fs::path& from, io::RunManifest& manifest,
                  std::vector<std::vector<std::pair<Real, std::string>>>& pvd) {
  for (auto& entries : pvd) {
    std::vector<std::pair<Real, std::string>> kept;
    for (auto& [t, file] : entries) {
      std::error_code ec;
      const fs::path src = from / file, dst = manifest.dir() / file;
      manifest.record(file);
      fs::remove(dst, ec);
      fs::create_hard_link(src, dst, ec);
      if (ec) fs::copy_file(src, dst, fs::copy_options::overwrite_existing, ec);
      if (ec) {
        spdlog::warn("frame {} of the checkpoint's run is not carried over: {}", src.string(),
                     ec.message());
        continue;
      }
      kept.emplace_back(t, std::move(file));
    }
    entries = std::move(kept);
  }
}

// history.csv as the checkpoint saw it (its first `bytes` bytes), from the run directory the
// checkpoint belongs to. When that is another directory and its history is gone, the new
// history starts at the checkpoint's step (a warning says so).
std::string history_at_checkpoint(const RunOptions& opt, const fs::path& from, std::uint64_t bytes,
                                  bool same_dir) {
  std::string history;
  std::error_code ec;
  if (fs::exists(from / "history.csv", ec)) {
    // Only what the checkpoint saw is read (the file may have grown long since).
    io::require_own_file(from / "history.csv", same_dir ? "--resume" : "--restart",
                         std::numeric_limits<std::uintmax_t>::max());
    std::ifstream in(from / "history.csv", std::ios::binary);
    history.resize(static_cast<std::size_t>(bytes));
    in.read(history.data(), static_cast<std::streamsize>(bytes));
    history.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  }
  if (history.size() == bytes) return history;
  if (same_dir || history.size() > 0)
    throw InputError({(from / "history.csv").string(), 0, 0}, same_dir ? "--resume" : "--restart",
                     fmt::format("the run's history.csv as the checkpoint saw it ({} bytes); it "
                                 "has {} (continue into the directory the run wrote, or from "
                                 "a checkpoint of this run)",
                                 bytes, history.size()));
  spdlog::warn("{} has no history.csv: {} starts its history at the checkpoint's step",
               from.string(), (opt.out_dir / "history.csv").string());
  return {};
}

template <int D>
RunResult run(const io::Config& c, const RunOptions& opt) {
  const auto wall_start = std::chrono::steady_clock::now();
  parallel::set_threads(opt.threads);
  auto parts = build_parts<D>(c);
  contact::Coupling<D> coupling(contact_settings(c), parts);
  Probes<D> probes(c, parts);  // the initial ground surface: before any step or resume
  LoopState st;
  std::unique_ptr<io::RunManifest> manifest;
  std::unique_ptr<Outputs<D>> outp;
  const bool resume = !opt.restart.empty();
  if (resume) {
    // Everything is checked before anything in the run directory changes.
    std::string payload;
    const io::CheckpointHeader h = io::read_checkpoint(opt.restart, payload);
    parts::StateReader rd(payload, opt.restart.string());
    if (h.dimension != D || h.scenario_hash != c.hash)
      rd.fail(
          fmt::format("it was written for another scenario (hash {} vs {} of this one, "
                      "after defaults and --set; resume with the same file and overrides)",
                      h.scenario_hash, c.hash));
    st.load(rd);
    std::vector<std::vector<std::pair<Real, std::string>>> pvd;
    const std::uint64_t history_bytes = Outputs<D>::load_pvd(rd, pvd);
    rd.tag("parts");
    if (rd.value<std::uint64_t>() != parts.size()) rd.fail("it holds another number of parts");
    for (auto& p : parts) {
      rd.tag(p->name());
      p->load_state(rd);
    }
    probes.load(rd);
    if (!rd.done()) rd.fail("it holds more than this scenario's state");
    const fs::path from = run_dir_of_checkpoint(opt.restart);
    const bool same_dir = same_directory(from, opt.out_dir);
    std::string history = history_at_checkpoint(opt, from, history_bytes, same_dir);
    if (!same_dir) io::prepare_new_run_directory(opt.out_dir, opt.force);
    manifest = std::make_unique<io::RunManifest>(opt.out_dir);
    if (!same_dir) {
      carry_frames(from, *manifest, pvd);
      io::write_run_command(opt.out_dir, opt.command);
    }
    manifest->record(io::kCommandName);
    const bool fresh_history = history.empty();
    outp = std::make_unique<Outputs<D>>(
        c, *manifest, parts, history_columns(parts, coupling, probes), std::move(history));
    if (fresh_history) outp->flush();
    outp->restore_pvd(std::move(pvd));
    spdlog::info("resumed from {} at step {}, t = {:.6g} s", opt.restart.string(), st.steps, st.t);
  } else {
    for (auto& p : parts)
      p->compute_forces(st.t);  // rates and sound speeds of the initial state
    coupling.apply(parts, 0);
    const StepLimit<D> lim = smallest_stable_step(parts, &coupling, Real(1));
    check_fixed_step(c, lim);
    check_step_count(c, lim.allowed_s);
    for (const auto& w : check_output_cadence(c, parts, lim.allowed_s, opt.out_dir))
      spdlog::warn("{}", w);
    io::prepare_new_run_directory(opt.out_dir, opt.force);
    manifest = std::make_unique<io::RunManifest>(opt.out_dir);
    manifest->record(io::kCommandName);
    io::write_run_command(opt.out_dir, opt.command);
    outp =
        std::make_unique<Outputs<D>>(c, *manifest, parts, history_columns(parts, coupling, probes));
  }
  Outputs<D>& out = *outp;
  for (const auto& w : c.warnings)
    spdlog::warn("{}", w);

  RunResult r;
  r.threads = parallel::max_threads();
  SignalGuard signals;

  Real& t = st.t;
  Energies e;
  auto summary = [&](const std::string& status, const std::string& message,
                     const std::vector<Diagnostic>& metrics = {}) {
    const Energies now = sum_energies(parts);
    EnergyTrack track = st.track;  // a copy: the scale it keeps must not move between rows
    const Real err = status == "failed" ? st.err : track.error(now);
    write_summary(c,
                  SummaryInputs{*manifest, opt.command, r, st.dt_min, st.dt_max, st.e0, now, err},
                  parts, status, message, &coupling, metrics);
  };
  if (!resume) {
    const std::vector<Energies> per = part_energies(parts);
    st.e0 = sum_energies(per);
    st.track = EnergyTrack{total_energy(st.e0), 0};
    st.err = st.track.error(st.e0);
    for (const Energies& x : per)
      st.part_total0_j.push_back(total_energy(x));
    out.frame(parts, t, "000000");
    out.history(0, t, 0, st.e0, total_energy(st.e0), st.err,
                history_values(per, coupling, probes, parts));
    st.next_frame_t = std::min(c.output.interval_s, c.end_time_s);
  }
  e = st.e0;
  r.steps = st.steps;
  r.first_step = st.steps;
  // A summary from the start (status "running"), brought up to date at every checkpoint: a run
  // that is killed or runs out of disk still leaves one for `crater report` and --resume.
  summary("running", "");
  Progress progress(c.end_time_s, opt.quiet, st.steps, t);
  const Real t_eps = 1e-12 * c.end_time_s;
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  };
  double last_checkpoint_s = 0;
  const double loop_start_s = elapsed();
  set_activity(Activity::TimeLoop);  // an allocation that fails from here on exits 3 (main.cpp)
  auto stamp = [&] {
    r.time_s = t;
    r.wall_s = elapsed();
    r.loop_s = r.wall_s - loop_start_s;
  };

  try {
    while (t < c.end_time_s - t_eps && (c.time.max_steps == 0 || r.steps < c.time.max_steps)) {
      const StepLimit<D> lim = smallest_stable_step(
          parts, &coupling, c.time.fixed_dt_s ? Real(1) : c.time.safety_factor);
      Real dt = c.time.fixed_dt_s ? *c.time.fixed_dt_s : lim.allowed_s;
      // Nothing limits the step when no part has live entities left (every element of a
      // solid eroded): go straight to the next output time.
      if (!c.time.fixed_dt_s && lim.dt_s == std::numeric_limits<Real>::infinity())
        dt = st.next_frame_t - t;
      // A fixed step accepted at t = 0 may exceed the limit later (an expanding charge speeds
      // up); going on would be unstable, so stop with the limiting part named.
      if (c.time.fixed_dt_s && *c.time.fixed_dt_s > lim.dt_s)
        throw NumericalError(lim.part, lim.detail.entity_id, t,
                             fmt::format("the fixed time step {:.4g} s exceeds the stable step "
                                         "{:.4g} s ({}); lower time.fixed_dt_s or unset it",
                                         *c.time.fixed_dt_s, lim.dt_s, lim.detail.reason));
      if (!(dt > 0) || !std::isfinite(dt))
        throw NumericalError(
            lim.part.empty() ? "?" : lim.part, lim.detail.entity_id, t,
            fmt::format("stable time step is {} ({})", lim.dt_s, lim.detail.reason));
      // Land exactly on output times and on the end time.
      bool at_frame = false;
      if (t + dt >= st.next_frame_t - t_eps) {
        dt = st.next_frame_t - t;
        at_frame = true;
      }
      st.dt = dt;
      st.dt_min = std::min(st.dt_min, dt);
      st.dt_max = std::max(st.dt_max, dt);

      for (auto& p : parts)
        p->advance(t, dt);
      t = at_frame ? st.next_frame_t : t + dt;
      ++r.steps;
      st.steps = r.steps;
      for (auto& p : parts)
        p->compute_forces(t);
      coupling.apply(parts, dt);
      for (auto& p : parts)
        if (auto fault = p->check())
          throw NumericalError(p->name(), fault->entity_id, t, fault->what);
      for (auto& p : parts)
        p->finish_step(dt);
      probes.after_step(parts, t);

      const bool last = t >= c.end_time_s - t_eps;
      if (r.steps % c.output.history_every == 0 || at_frame || last) {
        const std::vector<Energies> per = part_energies(parts);
        e = sum_energies(per);
        st.err = st.track.error(e);
        out.history(r.steps, t, dt, e, total_energy(e), st.err,
                    history_values(per, coupling, probes, parts));
        guard_energy(c, st, per, parts);
      }
      if (at_frame) {
        out.frame(parts, t, fmt::format("{:06d}", st.frame));
        ++st.frame;
        st.next_frame_t = std::min(c.output.interval_s * static_cast<Real>(st.frame), c.end_time_s);
        out.flush();
      }
      progress.update(r.steps, t, dt);

      const int sig = g_signal.load();
      const bool due =
          (c.output.checkpoint_every_steps > 0 && r.steps % c.output.checkpoint_every_steps == 0) ||
          (c.output.checkpoint_every_s > 0 &&
           elapsed() - last_checkpoint_s >= c.output.checkpoint_every_s);
      if ((due || sig != 0) && !last) {
        out.flush();
        write_checkpoint<D>(c, *manifest, st, out, parts, probes);
        stamp();
        if (sig == 0) summary("running", "");
        last_checkpoint_s = elapsed();
      }
      if (sig != 0 && !last) {
        stamp();
        summary("interrupted", fmt::format("stopped by signal {} at step {}; resume with: crater "
                                           "run --resume {}",
                                           sig, r.steps, opt.out_dir.string()));
        throw Interrupted(sig, r.steps, t);
      }
    }
  } catch (const NumericalError& ne) {
    // The state now in memory is the last one whose forces were finite: write it for the
    // user to look at (<part>_failure.vtu), with the history so far and a failed summary.
    out.frame(parts, t, "failure");
    stamp();
    out.flush();
    summary("failed", ne.what());
    throw;
  } catch (const Interrupted&) {
    throw;
  } catch (const std::exception& ex) {
    // A write that failed (a full disk): the summary says so when there is room for it; the
    // newest complete checkpoint is where --resume continues from.
    stamp();
    try {
      summary("failed", std::string(ex.what()) + "; resume with: crater run --resume " +
                            opt.out_dir.string());
    } catch (const std::exception&) {
      // No room even for the summary: the one of the last checkpoint stays.
    }
    throw;
  }
  stamp();
  progress.finish(r.steps, t, st.dt);
  out.flush();
  std::vector<Diagnostic> metrics = probes.finish(parts, opt.out_dir);
  if (fs::exists(opt.out_dir / "surface_profile.csv")) manifest->record("surface_profile.csv");
  summary("completed", "", metrics);
  return r;
}

template <int D>
std::vector<PartReport> check(const io::Config& c) {
  auto parts = build_parts<D>(c);
  contact::Coupling<D> coupling(contact_settings(c), parts);
  std::vector<PartReport> reports;
  for (auto& p : parts) {
    p->compute_forces(0);
    reports.push_back({p->name(), p->method(), p->count(), p->mass_kg(), p->stable_step()});
  }
  if (!coupling.empty()) {
    const StableStep s = coupling.stable_step(parts);
    reports.push_back({"contacts", "contact", static_cast<Index>(c.contacts.size()), 0, s});
  }
  const StepLimit<D> lim = smallest_stable_step(parts, &coupling, Real(1));
  check_fixed_step(c, lim);
  check_step_count(c, lim.allowed_s);
  for (const auto& w : check_output_cadence(c, parts, lim.allowed_s, {}))
    spdlog::warn("{}", w);
  return reports;
}

}  // namespace

std::vector<PartReport> check_scenario(const io::Config& config) {
  set_activity(Activity::Setup);
  require_memory(config);  // before any part is built
  return config.dimension == 2 ? check<2>(config) : check<3>(config);
}

RunResult run_scenario(const io::Config& config, const RunOptions& options) {
  set_activity(Activity::Setup);
  require_memory(config);  // before any part is built or the run directory touched
  return config.dimension == 2 ? run<2>(config, options) : run<3>(config, options);
}

}  // namespace crater::solver
