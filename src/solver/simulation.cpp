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
#include "dem/dem_part.hpp"
#include "fem/fem_part.hpp"
#include "io/output/atomic_file.hpp"
#include "io/output/json.hpp"
#include "io/output/vtu_writer.hpp"
#include "parallel/parallel.hpp"
#include "solver/probes.hpp"
#include "solver/progress.hpp"
#include "sph/sph_part.hpp"

namespace crater::solver {
namespace fs = std::filesystem;

// ---- part construction: one line per method ------------------------------------------------

template <int D>
std::vector<std::unique_ptr<Part<D>>> build_parts(const io::Config& config) {
  std::vector<std::unique_ptr<Part<D>>> parts;
  for (const auto& pc : config.parts) {
    if (pc.method == "sph") parts.push_back(sph::make_sph_part<D>(config, pc));
    if (pc.method == "dem") parts.push_back(dem::make_dem_part<D>(config, pc));
    if (pc.method == "fem") parts.push_back(fem::make_fem_part<D>(config, pc));
  }
  return parts;
}

template std::vector<std::unique_ptr<Part<2>>> build_parts<2>(const io::Config&);
template std::vector<std::unique_ptr<Part<3>>> build_parts<3>(const io::Config&);

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
  Outputs(const io::Config& c, const fs::path& dir,
          const std::vector<std::unique_ptr<Part<D>>>& parts,
          const std::vector<std::string>& extra_columns, std::string history_prefix = {})
      : config_(c), dir_(dir), history_(dir / "history.csv") {
    for (const auto& p : parts)
      pvd_.emplace_back(dir / (p->name() + ".pvd"));
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

  void save(io::StateWriter& w) const {
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
  static std::uint64_t load_pvd(io::StateReader& r,
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

 private:
  const io::Config& config_;
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

void prepare_out_dir(const fs::path& dir, bool force) {
  std::error_code ec;
  if (fs::exists(dir / "summary.json", ec) || fs::exists(dir / "history.csv", ec)) {
    if (!force)
      throw InputError({dir.string(), 0, 0}, "--out",
                       "the directory already holds a run; pass --force to overwrite it or "
                       "choose another --out");
    for (const auto& e : fs::directory_iterator(dir, ec)) {
      const auto ext = e.path().extension();
      if (ext == ".vtu" || ext == ".pvd" || ext == ".csv" || ext == ".json" || ext == ".tmp")
        fs::remove(e.path(), ec);
    }
  }
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw InputError({dir.string(), 0, 0}, "--out",
                     "cannot create the output directory: " + ec.message());
}

struct EnergyTrack {
  Real initial_total = 0;
  Real scale = 0;  // largest kinetic + internal seen, the denominator of the relative error
  Real error(const Energies& e) {
    scale = std::max(scale, std::abs(e.kinetic_j) + std::abs(e.internal_j));
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

template <int D>
void write_summary(const io::Config& c, const fs::path& dir,
                   const std::vector<std::unique_ptr<Part<D>>>& parts, const RunResult& r,
                   Real dt_min, Real dt_max, const Energies& e0, const Energies& e,
                   Real energy_error, const std::string& status, const std::string& message,
                   const contact::Coupling<D>* coupling = nullptr,
                   const std::vector<Diagnostic>& metrics = {}) {
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
  j.end_object();
  j.end_object();
  io::write_file_atomic(dir / "summary.json", j.str());
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

  void save(io::StateWriter& w) const {
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
  }
  void load(io::StateReader& r) {
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
  }
};

template <int D>
void write_checkpoint(const io::Config& c, const fs::path& dir, const LoopState& st,
                      const Outputs<D>& out, const std::vector<std::unique_ptr<Part<D>>>& parts,
                      const Probes<D>& probes) {
  io::StateWriter w;
  st.save(w);
  out.save(w);
  w.tag("parts");
  w.value(static_cast<std::uint64_t>(parts.size()));
  for (const auto& p : parts) {
    w.tag(p->name());
    p->save_state(w);
  }
  probes.save(w);
  const fs::path cdir = dir / "checkpoints";
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

template <int D>
RunResult run(const io::Config& c, const RunOptions& opt) {
  const auto wall_start = std::chrono::steady_clock::now();
  parallel::set_threads(opt.threads);
  auto parts = build_parts<D>(c);
  contact::Coupling<D> coupling(c, parts);
  Probes<D> probes(c, parts);  // the initial ground surface: before any step or resume
  LoopState st;
  std::unique_ptr<Outputs<D>> outp;
  const bool resume = !opt.restart.empty();
  if (resume) {
    // Everything is checked before anything in the run directory changes.
    std::string payload;
    const io::CheckpointHeader h = io::read_checkpoint(opt.restart, payload);
    io::StateReader rd(payload, opt.restart.string());
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
    std::string history;
    {
      std::ifstream in(opt.out_dir / "history.csv", std::ios::binary);
      history.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    if (history.size() < history_bytes)
      throw InputError({(opt.out_dir / "history.csv").string(), 0, 0}, "--resume",
                       fmt::format("the run's history.csv as the checkpoint saw it ({} bytes); "
                                   "it has {} (resume into the directory the run wrote)",
                                   history_bytes, history.size()));
    history.resize(history_bytes);
    outp = std::make_unique<Outputs<D>>(
        c, opt.out_dir, parts, history_columns(parts, coupling, probes), std::move(history));
    outp->restore_pvd(std::move(pvd));
    spdlog::info("resumed from {} at step {}, t = {:.6g} s", opt.restart.string(), st.steps, st.t);
  } else {
    for (auto& p : parts)
      p->compute_forces(st.t);  // rates and sound speeds of the initial state
    coupling.apply(parts, 0);
    check_fixed_step(c, smallest_stable_step(parts, &coupling, Real(1)));
    prepare_out_dir(opt.out_dir, opt.force);
    outp = std::make_unique<Outputs<D>>(c, opt.out_dir, parts,
                                        history_columns(parts, coupling, probes));
  }
  Outputs<D>& out = *outp;
  for (const auto& w : c.warnings)
    spdlog::warn("{}", w);

  RunResult r;
  r.threads = parallel::max_threads();
  SignalGuard signals;

  Real& t = st.t;
  Energies e;
  if (!resume) {
    const std::vector<Energies> per = part_energies(parts);
    st.e0 = sum_energies(per);
    st.track = EnergyTrack{total_energy(st.e0), 0};
    st.err = st.track.error(st.e0);
    out.frame(parts, t, "000000");
    out.history(0, t, 0, st.e0, total_energy(st.e0), st.err,
                history_values(per, coupling, probes, parts));
    st.next_frame_t = std::min(c.output.interval_s, c.end_time_s);
  }
  e = st.e0;
  r.steps = st.steps;
  r.first_step = st.steps;
  Progress progress(c.end_time_s, opt.quiet, st.steps, t);
  const Real t_eps = 1e-12 * c.end_time_s;
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  };
  double last_checkpoint_s = 0;
  const double loop_start_s = elapsed();

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
        write_checkpoint<D>(c, opt.out_dir, st, out, parts, probes);
        last_checkpoint_s = elapsed();
      }
      if (sig != 0 && !last) {
        r.time_s = t;
        r.wall_s = elapsed();
        r.loop_s = r.wall_s - loop_start_s;
        e = sum_energies(parts);
        write_summary(c, opt.out_dir, parts, r, st.dt_min, st.dt_max, st.e0, e, st.track.error(e),
                      "interrupted",
                      fmt::format("stopped by signal {} at step {}; resume with --resume {}", sig,
                                  r.steps, opt.out_dir.string()),
                      &coupling);
        throw Interrupted(sig, r.steps, t);
      }
    }
  } catch (const NumericalError& ne) {
    // The state now in memory is the last one whose forces were finite: write it for the
    // user to look at (<part>_failure.vtu), with the history so far and a failed summary.
    out.frame(parts, t, "failure");
    r.time_s = t;
    r.wall_s = elapsed();
    r.loop_s = r.wall_s - loop_start_s;
    out.flush();
    write_summary(c, opt.out_dir, parts, r, st.dt_min, st.dt_max, st.e0, sum_energies(parts),
                  st.err, "failed", ne.what(), &coupling);
    throw;
  }
  r.time_s = t;
  r.wall_s = elapsed();
  r.loop_s = r.wall_s - loop_start_s;
  progress.finish(r.steps, t, st.dt);
  e = sum_energies(parts);
  out.flush();
  write_summary(c, opt.out_dir, parts, r, st.dt_min, st.dt_max, st.e0, e, st.track.error(e),
                "completed", "", &coupling, probes.finish(parts, opt.out_dir));
  return r;
}

template <int D>
std::vector<PartReport> check(const io::Config& c) {
  auto parts = build_parts<D>(c);
  contact::Coupling<D> coupling(c, parts);
  std::vector<PartReport> reports;
  for (auto& p : parts) {
    p->compute_forces(0);
    reports.push_back({p->name(), p->method(), p->count(), p->mass_kg(), p->stable_step()});
  }
  if (!coupling.empty()) {
    const StableStep s = coupling.stable_step(parts);
    reports.push_back({"contacts", "contact", static_cast<Index>(c.contacts.size()), 0, s});
  }
  check_fixed_step(c, smallest_stable_step(parts, &coupling, Real(1)));
  return reports;
}

}  // namespace

std::vector<PartReport> check_scenario(const io::Config& config) {
  return config.dimension == 2 ? check<2>(config) : check<3>(config);
}

RunResult run_scenario(const io::Config& config, const RunOptions& options) {
  return config.dimension == 2 ? run<2>(config, options) : run<3>(config, options);
}

}  // namespace crater::solver
