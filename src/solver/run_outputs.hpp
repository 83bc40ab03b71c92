// What a run writes as it goes: the VTU frames with their PVD collections and history.csv
// (Outputs), the history's columns after the energies, and summary.json (write_summary).
#pragma once

#include <fmt/format.h>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "contact/coupling.hpp"
#include "io/output/atomic_file.hpp"
#include "io/output/json.hpp"
#include "io/output/run_directory.hpp"
#include "io/output/vtu_writer.hpp"
#include "io/scenario/config.hpp"
#include "parts/state_archive.hpp"
#include "solver/energy_balance.hpp"
#include "solver/probes.hpp"
#include "solver/simulation.hpp"

namespace crater::solver {
namespace fs = std::filesystem;

template <int D>
class Outputs {
 public:
  // A new run writes history.csv's header; a resumed one keeps the file's first
  // `resume_history` bytes (what it held at the checkpoint) and goes on from there.
  // `extra_columns` follow the energy columns (history_columns: contact forces, part totals).
  // gauges.csv ([[gauges]]) likewise: `gauges_header` for a new run (empty: no gauges), the
  // file's first bytes as the checkpoint saw them for a resumed one.
  // On several ranks (`ranks`, Part::distribute) only the root rank writes: the others pass a
  // null manifest and write nothing, but take part in gathering the frames (frame()), or, with
  // output.pieces = "ranks", write their pieces of them into `dir`/pieces/ (collective: the
  // root has made the run directory when the others go on).
  Outputs(const io::Config& c, io::RunManifest* manifest, const fs::path& dir,
          const parallel::Comm* ranks, const std::vector<std::unique_ptr<Part<D>>>& parts,
          const std::vector<std::string>& extra_columns, std::string history_prefix = {},
          const std::string& gauges_header = {}, std::string gauges_prefix = {})
      : config_(c),
        writer_(manifest),
        dir_(dir),
        ranks_(ranks && ranks->size() > 1 ? ranks : nullptr),
        pieces_(ranks_ && c.output.pieces == io::FramePieces::Ranks && c.output.vtu) {
    if (pieces_) ranks_->barrier();
    if (!writer_) return;
    io::RunManifest& m = *writer_;
    history_.emplace(open_history(m));
    if (!gauges_header.empty()) {
      m.record("gauges.csv");
      gauges_.emplace(dir_ / "gauges.csv");
      const std::string& start = gauges_prefix.empty() ? gauges_header : gauges_prefix;
      gauges_->write(start);
      gauges_bytes_ = start.size();
    }
    for (const auto& p : parts) {
      m.record(p->name() + ".pvd");
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
    history_->write(history_prefix);
    history_bytes_ = history_prefix.size();
  }

  void save(parts::StateWriter& w) const {
    w.tag("outputs");
    w.value(static_cast<std::uint64_t>(history_bytes_));
    w.value(static_cast<std::uint64_t>(gauges_bytes_));
    w.value(static_cast<std::uint64_t>(pvd_.size()));
    for (const auto& p : pvd_) {
      w.value(static_cast<std::uint64_t>(p.entries().size()));
      for (const auto& [t, f] : p.entries()) {
        w.value(t);
        w.string(f);
      }
    }
  }
  /// The PVD entries of a checkpoint and the length gauges.csv had then; returns the length
  /// history.csv had.
  static std::uint64_t load_pvd(parts::StateReader& r,
                                std::vector<std::vector<std::pair<Real, std::string>>>& pvd,
                                std::uint64_t& gauges_bytes) {
    r.tag("outputs");
    const auto bytes = r.value<std::uint64_t>();
    gauges_bytes = r.value<std::uint64_t>();
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
      if (pieces_) {
        write_pieces(*parts[k], k, t, tag);
        continue;
      }
      // A part spread over ranks is gathered by every rank, and written by the root.
      const std::optional<parts::GatheredPoints<D>> gathered = parts[k]->gathered_points();
      if (!writer_) continue;
      const std::string file = fmt::format("{}_{}.vtu", parts[k]->name(), tag);
      writer_->record(file);
      if (gathered)
        write_gathered(*gathered, dir_ / file, t);
      else
        write_part(*parts[k], dir_ / file, t);
      if (tag != "failure") pvd_[k].add(t, file);
    }
  }

  // output.pieces = "ranks": this rank's piece of part k's frame, pieces/<part>_<tag>_<rank>.vtu,
  // and the root's PVTU over every rank's, <part>_<tag>.pvtu, in the PVD.
  void write_pieces(const Part<D>& part, std::size_t k, Real t, const std::string& tag) {
    const std::optional<parts::GatheredPoints<D>> piece = part.own_piece();  // collective (FEM)
    if (!piece) throw std::logic_error("part '" + part.name() + "' is not spread: no piece");
    const std::string stem = fmt::format("{}_{}", part.name(), tag);
    auto piece_name = [&](int r) { return fmt::format("pieces/{}_{:04d}.vtu", stem, r); };
    std::error_code ec;
    fs::create_directories(dir_ / "pieces", ec);  // every rank; one of them makes it
    if (!fs::is_directory(dir_ / "pieces"))
      throw std::runtime_error("cannot create " + (dir_ / "pieces").string() + ": " + ec.message());
    write_gathered(*piece, dir_ / piece_name(ranks_->rank()), t);
    if (!writer_) return;
    writer_->record("pieces/");
    std::vector<std::string> names;
    for (int r = 0; r < ranks_->size(); ++r)
      names.push_back(piece_name(r));
    const std::string file = stem + ".pvtu";
    writer_->record(file);
    io::write_pvtu(dir_ / file, vtu_arrays(piece->point.views()), vtu_arrays(piece->cell.views()),
                   names);
    if (tag != "failure") pvd_[k].add(t, file);
  }

  // A particle part's points, or a mesh part's cells with their fields (a rank's piece may hold
  // none of its elements: its cell arrays are still written, empty, as the PVTU declares them).
  void write_gathered(const parts::GatheredPoints<D>& g, const fs::path& path, Real t) {
    if (g.cell_types.empty() && g.cell.infos.empty())
      return write_points(g.points, g.point.views(), path, t);
    Geometry<D> cells;
    cells.points = &g.points;
    cells.connectivity = g.connectivity;
    cells.offsets = g.offsets;
    cells.cell_types = g.cell_types;
    write_points(g.points, g.point.views(), path, t, &cells, g.cell.views());
  }

  void write_part(const Part<D>& p, const fs::path& path, Real t) {
    const Geometry<D> g = p.geometry();
    write_points(*g.points, p.point_fields(), path, t, &g, p.cell_fields());
  }

  void write_points(const std::vector<Vec<D>>& points, const std::vector<fields::FieldView>& pf,
                    const fs::path& path, Real t, const Geometry<D>* cells = nullptr,
                    const std::vector<fields::FieldView>& cf = {}) {
    io::VtuMesh mesh;
    mesh.num_points = static_cast<Index>(points.size());
    mesh.dimension = D;
    mesh.points = points.empty() ? nullptr : points.front().data();
    if (cells && !cells->connectivity.empty()) {
      mesh.connectivity = &cells->connectivity;
      mesh.offsets = &cells->offsets;
      mesh.cell_types = &cells->cell_types;
    }
    io::write_vtu(path, t, mesh, vtu_arrays(pf), vtu_arrays(cf),
                  config_.output.vtu_encoding == io::VtuEncoding::Base64 ? io::VtuFormat::Base64
                                                                         : io::VtuFormat::Appended);
  }

  static std::vector<io::VtuArray> vtu_arrays(const std::vector<fields::FieldView>& views) {
    std::vector<io::VtuArray> out;
    for (const auto& v : views)
      out.push_back(io::VtuArray{v.info->name, v.components, v.real_data, v.integer_data,
                                 v.components == D && D == 2});
    return out;
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
    if (!writer_) return;
    history_->write(row);
    history_bytes_ += row.size();
  }
  void gauges(const std::string& row) {
    if (!writer_) return;
    gauges_->write(row);
    gauges_bytes_ += row.size();
  }
  void flush() {
    if (history_) history_->flush();
    if (gauges_) gauges_->flush();
  }
  io::RunManifest& manifest() { return *writer_; }

 private:
  static fs::path open_history(io::RunManifest& manifest) {
    manifest.record("history.csv");
    return manifest.dir() / "history.csv";
  }

  const io::Config& config_;
  io::RunManifest* writer_;  // null: another rank writes
  fs::path dir_;
  const parallel::Comm* ranks_;  // several ranks; null on one
  bool pieces_;                  // output.pieces = "ranks" on several ranks
  std::optional<io::AppendFile> history_;
  std::size_t history_bytes_ = 0;
  std::optional<io::AppendFile> gauges_;
  std::size_t gauges_bytes_ = 0;
  std::vector<io::PvdCollection> pvd_;
};

// history.csv's columns after the energies: the contacts' forces, the probes', the parts' own
// (moving walls), then (runs of several parts) each part's own total energy, energy_<part>_j,
// so that a drift can be traced to a part (the parts' totals add up to total_j), and the kinetic
// and internal energy each part holds, kinetic_<part>_j and internal_<part>_j.
template <int D>
std::vector<std::string> history_columns(const std::vector<std::unique_ptr<Part<D>>>& parts,
                                         const contact::Coupling<D>& coupling,
                                         const Probes<D>& probes) {
  std::vector<std::string> columns = coupling.history_columns();
  for (auto& col : probes.history_columns())
    columns.push_back(std::move(col));
  for (const auto& p : parts)
    for (auto& col : p->history_columns())
      columns.push_back(std::move(col));
  if (parts.size() > 1) {
    for (const auto& p : parts)
      columns.push_back("energy_" + p->name() + "_j");
    // What each part holds (its contact work aside): where the charge's energy went.
    for (const auto& p : parts) {
      columns.push_back("kinetic_" + p->name() + "_j");
      columns.push_back("internal_" + p->name() + "_j");
    }
  }
  return columns;
}
template <int D>
std::vector<Real> history_values(const std::vector<Energies>& per,
                                 const contact::Coupling<D>& coupling, Probes<D>& probes,
                                 const std::vector<std::unique_ptr<Part<D>>>& parts,
                                 const parallel::Comm* spread = nullptr) {
  std::vector<Real> values = coupling.history_values();
  for (Real v : probes.history_values(parts, spread))
    values.push_back(v);
  for (const auto& p : parts)
    for (Real v : p->history_values())
      values.push_back(v);
  if (per.size() > 1) {
    for (const Energies& e : per)
      values.push_back(total_energy(e));
    for (const Energies& e : per) {
      values.push_back(e.kinetic_j);
      values.push_back(e.internal_j);
    }
  }
  return values;
}

// summary.json's "run" block: how the run was started (crater-command.toml holds the same).
inline void write_command(io::JsonWriter& j, const io::RunCommand& command) {
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
  io::RunManifest* manifest;  // null: another rank writes the summary
  const io::RunCommand& command;
  const RunResult& r;
  Real dt_min, dt_max;
  const Energies& e0;
  const Energies& e;
  Real energy_error;
};

// The contacts' views on ranks: gathered, reused by the step limits, the whole particle views
// gathered without their unchanged masses, ids and radii, and the contact zones' views with the
// share of their parts' particles they held.
inline void write_contact_views(io::JsonWriter& j, const contact::ViewCounts& views) {
  j.key("contact_views").begin_object();
  j.field("gathers", static_cast<double>(views.gathers));
  j.field("reused_for_limits", static_cast<double>(views.reused_for_limits));
  j.field("static_fields_kept", static_cast<double>(views.static_kept));
  j.field("zone_views", static_cast<double>(views.zone_views));
  j.field("zone_share", views.zone_whole_particles > 0
                            ? static_cast<double>(views.zone_particles) /
                                  static_cast<double>(views.zone_whole_particles)
                            : 0.0);
  j.end_object();
}

/// On ranks, every rank's loop time and its time in MPI's calls, then its time_by_part (each
/// part, then the contacts) and the time in MPI's calls of each of those, rank after rank (one
/// all-gather; collective); empty on one rank.
inline std::vector<double> times_by_rank(const RunResult& r) {
  const parallel::Comm& comm = parallel::Comm::world();
  if (comm.size() < 2) return {};
  const RunResult::TimeByPart& tp = r.time_by_part;
  std::vector<double> mine{r.loop_s, r.loop_mpi_s};
  for (std::size_t k = 0; k < tp.parts_s.size(); ++k) {
    mine.push_back(tp.parts_s[k].second);
    mine.push_back(k < tp.parts_mpi_s.size() ? tp.parts_mpi_s[k] : 0.0);
  }
  mine.push_back(tp.contacts_s);
  mine.push_back(tp.contacts_mpi_s);
  return parallel::all_gather(comm, std::span<const double>(mine));
}

/// run.time_by_rank_s: per rank, where its loop went (as time_by_part_s, which is rank 0's), and
/// how much of it, and of each stage, in MPI's calls (`mpi`, `mpi_by_stage`: waiting for the
/// other ranks and moving bytes), so that a rank waiting for another shows.
inline void write_times_by_rank(io::JsonWriter& j, const RunResult& r,
                                const std::vector<double>& by_rank) {
  const std::vector<std::pair<std::string, double>>& parts = r.time_by_part.parts_s;
  const std::size_t per = 2 * parts.size() + 4;
  const std::size_t ranks = by_rank.size() / per;
  auto column = [&](std::string_view name, std::size_t k) {
    j.key(name).begin_array();
    for (std::size_t q = 0; q < ranks; ++q)
      j.value(by_rank[q * per + k]);
    j.end_array();
  };
  j.key("time_by_rank_s").begin_object();
  column("loop", 0);
  column("mpi", 1);
  j.key("parts").begin_object();
  for (std::size_t k = 0; k < parts.size(); ++k)
    column(parts[k].first, 2 + 2 * k);
  j.end_object();
  column("contacts", per - 2);
  j.key("mpi_by_stage").begin_object();
  for (std::size_t k = 0; k < parts.size(); ++k)
    column(parts[k].first, 3 + 2 * k);
  column("contacts", per - 1);
  j.end_object();
  j.end_object();
}

template <int D>
void write_summary(const io::Config& c, const SummaryInputs& in,
                   const std::vector<std::unique_ptr<Part<D>>>& parts, const std::string& status,
                   const std::string& message, const contact::Coupling<D>* coupling = nullptr,
                   const std::vector<Diagnostic>& metrics = {}) {
  const RunResult& r = in.r;
  // Collective on ranks: every rank asks, in the same order.
  std::vector<std::pair<std::string, std::vector<Diagnostic>>> shares;
  for (const auto& p : parts)
    if (auto f = p->rank_figures(); !f.empty()) shares.emplace_back(p->name(), std::move(f));
  const std::vector<double> by_rank = times_by_rank(r);
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
  if (c.time.multi_rate) {
    // Multi-rate: a step is a cycle, min_s / max_s its base step; each part's own steps.
    j.field("multi_rate_max_ratio", static_cast<std::int64_t>(c.time.multi_rate_max_ratio));
    j.key("steps_by_part").begin_object();
    for (const auto& [name, n] : r.steps_by_part)
      j.field(name, n);
    j.end_object();
  }
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
  if (r.ranks > 1) {
    j.field("ranks", r.ranks);
    // What the particle parts' cuts weigh when made again (domain.balance).
    j.field("balance", c.domain.balance_by_time ? "time" : "count");
  }
  if (!shares.empty()) {
    // Each spread part's share among the ranks (Part::rank_figures).
    j.key("ranks_by_part").begin_object();
    for (const auto& [name, figures] : shares) {
      j.key(name).begin_object();
      for (const auto& d : figures)
        j.field(d.name, d.value);
      j.end_object();
    }
    j.end_object();
  }
  if (!by_rank.empty()) write_times_by_rank(j, r, by_rank);
  if (const auto views = coupling ? coupling->view_counts() : std::nullopt)
    write_contact_views(j, *views);
  // The time loop alone (no setup, no final output): what the peers' "Loop time" counts.
  j.field("loop_time_s", r.loop_s);
  // This process's steps over its own wall time (a resumed run counts from where it resumed).
  j.field("steps_per_s",
          r.wall_s > 0 ? static_cast<double>(r.steps - r.first_step) / r.wall_s : 0.0);
  if (r.first_step > 0) j.field("resumed_at_step", static_cast<double>(r.first_step));
  // Where loop_time_s went: each part's stages, the contacts, probes, outputs, the rest.
  const RunResult::TimeByPart& tp = r.time_by_part;
  j.key("time_by_part_s").begin_object();
  j.key("parts").begin_object();
  for (const auto& [name, s] : tp.parts_s)
    j.field(name, s);
  j.end_object();
  j.field("contacts", tp.contacts_s).field("probes", tp.probes_s);
  j.field("output", tp.output_s).field("other", tp.other_s);
  j.end_object();
  write_command(j, in.command);
  j.end_object();
  j.end_object();
  if (!in.manifest) return;  // another rank writes it
  in.manifest->record("summary.json");
  io::write_file_atomic(in.manifest->dir() / "summary.json", j.str());
}

}  // namespace crater::solver
