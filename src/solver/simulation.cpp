#include "solver/simulation.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "dem/dem_part.hpp"
#include "io/output/atomic_file.hpp"
#include "io/output/json.hpp"
#include "io/output/vtu_writer.hpp"
#include "parallel/parallel.hpp"
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
  }
  return parts;
}

template std::vector<std::unique_ptr<Part<2>>> build_parts<2>(const io::Config&);
template std::vector<std::unique_ptr<Part<3>>> build_parts<3>(const io::Config&);

namespace {

template <int D>
struct StepLimit {
  Real dt_s = std::numeric_limits<Real>::infinity();
  const Part<D>* part = nullptr;
  StableStep detail;
};

template <int D>
StepLimit<D> smallest_stable_step(const std::vector<std::unique_ptr<Part<D>>>& parts) {
  StepLimit<D> lim;
  for (const auto& p : parts) {
    const StableStep s = p->stable_step();
    if (s.dt_s < lim.dt_s) lim = {s.dt_s, p.get(), s};
  }
  return lim;
}

// The user's fixed step must not exceed the stable limit (READING-NOTES: the paper's 1 us
// does); the error names the limiting part.
template <int D>
void check_fixed_step(const io::Config& c, const StepLimit<D>& lim) {
  if (!c.time.fixed_dt_s || !lim.part) return;
  if (*c.time.fixed_dt_s > lim.dt_s)
    throw InputError(c.time.fixed_dt_where, "time.fixed_dt_s",
                     fmt::format("fixed step {:.4g} s exceeds the stable limit {:.4g} s of part "
                                 "'{}' ({}, entity {}); use at most {:.4g} s or unset it",
                                 *c.time.fixed_dt_s, lim.dt_s, lim.part->name(), lim.detail.reason,
                                 lim.detail.entity_id, lim.dt_s));
}

// ---- outputs -------------------------------------------------------------------------------

template <int D>
class Outputs {
 public:
  Outputs(const io::Config& c, const fs::path& dir,
          const std::vector<std::unique_ptr<Part<D>>>& parts)
      : config_(c), dir_(dir), history_(dir / "history.csv") {
    for (const auto& p : parts)
      pvd_.emplace_back(dir / (p->name() + ".pvd"));
    history_.write(
        "step,time_s,dt_s,kinetic_j,internal_j,external_work_j,damping_j,hourglass_j,contact_j,"
        "eroded_j,total_j,energy_error\n");
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

  void history(Index step, Real t, Real dt, const Energies& e, Real total, Real error) {
    history_.write(
        fmt::format("{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},"
                    "{:.17g},{:.17g},{:.17g}\n",
                    step, t, dt, e.kinetic_j, e.internal_j, e.external_work_j, e.damping_j,
                    e.hourglass_j, e.contact_j, e.eroded_j, total, error));
  }
  void flush() { history_.flush(); }

 private:
  const io::Config& config_;
  fs::path dir_;
  io::AppendFile history_;
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

template <int D>
Energies sum_energies(const std::vector<std::unique_ptr<Part<D>>>& parts) {
  Energies e;
  for (const auto& p : parts)
    e += p->energies();
  return e;
}

template <int D>
void write_summary(const io::Config& c, const fs::path& dir,
                   const std::vector<std::unique_ptr<Part<D>>>& parts, const RunResult& r,
                   Real dt_min, Real dt_max, const Energies& e0, const Energies& e,
                   Real energy_error, const std::string& status, const std::string& message) {
  io::JsonWriter j;
  j.begin_object();
  j.field("crater_version", CRATER_VERSION);
  j.field("status", status);
  if (!message.empty()) j.field("message", message);
  j.key("scenario").begin_object();
  j.field("name", c.name).field("file", c.file).field("hash", c.hash);
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
  j.end_object();
  // Everything above is identical for any thread count; this block is not.
  j.key("run").begin_object();
  j.field("wall_time_s", r.wall_s).field("threads", r.threads);
  j.field("steps_per_s", r.wall_s > 0 ? static_cast<double>(r.steps) / r.wall_s : 0.0);
  j.end_object();
  j.end_object();
  io::write_file_atomic(dir / "summary.json", j.str());
}

template <int D>
RunResult run(const io::Config& c, const RunOptions& opt) {
  const auto wall_start = std::chrono::steady_clock::now();
  parallel::set_threads(opt.threads);
  auto parts = build_parts<D>(c);
  Real t = 0;
  for (auto& p : parts)
    p->compute_forces(t);  // rates and sound speeds of the initial state
  check_fixed_step(c, smallest_stable_step(parts));
  prepare_out_dir(opt.out_dir, opt.force);
  for (const auto& w : c.warnings)
    spdlog::warn("{}", w);

  Outputs<D> out(c, opt.out_dir, parts);
  Progress progress(c.end_time_s, opt.quiet);
  RunResult r;
  r.threads = parallel::max_threads();

  const Energies e0 = sum_energies(parts);
  EnergyTrack track{total_energy(e0), 0};
  Energies e = e0;
  Real err = track.error(e0);
  out.frame(parts, t, "000000");
  out.history(0, t, 0, e0, total_energy(e0), err);

  Real dt_min = std::numeric_limits<Real>::infinity(), dt_max = 0, dt = 0;
  Index frame = 1;
  Real next_frame_t = std::min(c.output.interval_s, c.end_time_s);
  const Real t_eps = 1e-12 * c.end_time_s;
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  };

  try {
    while (t < c.end_time_s - t_eps && (c.time.max_steps == 0 || r.steps < c.time.max_steps)) {
      const StepLimit<D> lim = smallest_stable_step(parts);
      dt = c.time.fixed_dt_s ? *c.time.fixed_dt_s : c.time.safety_factor * lim.dt_s;
      // A fixed step accepted at t = 0 may exceed the limit later (an expanding charge speeds
      // up); going on would be unstable, so stop with the limiting part named.
      if (c.time.fixed_dt_s && *c.time.fixed_dt_s > lim.dt_s)
        throw NumericalError(lim.part->name(), lim.detail.entity_id, t,
                             fmt::format("the fixed time step {:.4g} s exceeds the stable step "
                                         "{:.4g} s ({}); lower time.fixed_dt_s or unset it",
                                         *c.time.fixed_dt_s, lim.dt_s, lim.detail.reason));
      if (!(dt > 0) || !std::isfinite(dt))
        throw NumericalError(
            lim.part ? lim.part->name() : "?", lim.detail.entity_id, t,
            fmt::format("stable time step is {} ({})", lim.dt_s, lim.detail.reason));
      // Land exactly on output times and on the end time.
      bool at_frame = false;
      if (t + dt >= next_frame_t - t_eps) {
        dt = next_frame_t - t;
        at_frame = true;
      }
      dt_min = std::min(dt_min, dt);
      dt_max = std::max(dt_max, dt);

      for (auto& p : parts)
        p->advance(t, dt);
      t = at_frame ? next_frame_t : t + dt;
      ++r.steps;
      for (auto& p : parts)
        p->compute_forces(t);
      for (auto& p : parts)
        if (auto fault = p->check())
          throw NumericalError(p->name(), fault->entity_id, t, fault->what);
      for (auto& p : parts)
        p->finish_step(dt);

      const bool last = t >= c.end_time_s - t_eps;
      if (r.steps % c.output.history_every == 0 || at_frame || last) {
        e = sum_energies(parts);
        err = track.error(e);
        out.history(r.steps, t, dt, e, total_energy(e), err);
      }
      if (at_frame) {
        out.frame(parts, t, fmt::format("{:06d}", frame));
        ++frame;
        next_frame_t = std::min(c.output.interval_s * static_cast<Real>(frame), c.end_time_s);
        out.flush();
      }
      progress.update(r.steps, t, dt);
    }
  } catch (const NumericalError& ne) {
    // The state now in memory is the last one whose forces were finite: write it for the
    // user to look at (<part>_failure.vtu), with the history so far and a failed summary.
    out.frame(parts, t, "failure");
    r.time_s = t;
    r.wall_s = elapsed();
    out.flush();
    write_summary(c, opt.out_dir, parts, r, dt_min, dt_max, e0, sum_energies(parts), err, "failed",
                  ne.what());
    throw;
  }
  r.time_s = t;
  r.wall_s = elapsed();
  progress.finish(r.steps, t, dt);
  e = sum_energies(parts);
  out.flush();
  write_summary(c, opt.out_dir, parts, r, dt_min, dt_max, e0, e, track.error(e), "completed", "");
  return r;
}

template <int D>
std::vector<PartReport> check(const io::Config& c) {
  auto parts = build_parts<D>(c);
  std::vector<PartReport> reports;
  for (auto& p : parts) {
    p->compute_forces(0);
    reports.push_back({p->name(), p->method(), p->count(), p->mass_kg(), p->stable_step()});
  }
  check_fixed_step(c, smallest_stable_step(parts));
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
