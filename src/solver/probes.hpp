// The paper's measurements ([probes]; docs/theory.md "Probes"): the plate's stresses, erosion
// and perforation, the ground surface (settlement, crater) and the plate-soil gap. They read
// the parts through what the writers see (geometry and output fields), so they measure what
// the VTU files show.
//
// Ground surface. The domain's horizontal extent is cut into columns of width ~b (the extent
// over a whole number of columns), each column into cells of height b. A cell's filled volume is F
// = (grain volume) / phi_ref + (volume of the plate's live elements), a grain or an element counted
// in the cell of its centre (an element only in a cell reaching into the soil's holes, where the
// plate was laid: pieces thrown up are not the ground), phi_ref the bed's packing fraction measured
// at t = 0 (median over cells inside the bed); F a reproducible sum of its terms (the same bits in
// any order: on ranks each adds its own grains and elements, the root merges). From the top down,
// the first non-empty cell c that with the cell below holds at least half a cell's worth (F_c +
// F_{c-1} >= b^D / 2) is the column's top; the surface height is the bottom of the cell below c
// plus (min(F_{c-1}, b^D) + F_c + F_{c+1}) / b^(D-1), the height the solid of those three cells
// would fill at the bed's packing (the floor counts as a full cell). A cell pair that half fills is
// "dense". The column's ground is what stands on its floor: from the bottom up, the dense cells
// until the first gap of more than three grain diameters (6 r_max; at the default b = 8 r_max, any
// cell that is not dense), where cells inside the regions the soil was laid around (the charge's,
// the plate's: soil.carve) make no gap (a cell reaching into them is counted with them); c is the
// last dense cell of it. Material above such a gap is in flight (ejecta, plate pieces) and is not
// the ground, however dense its clumps. Nor is a grain in free flight (no contact, and fast enough
// to rise more than its own diameter: |v|^2 > 4 g r), however dense the stream it flies in. The
// packing's density varies from cell to cell: the surface of a flat bed comes out within about a
// grain diameter.
//   2D: surface_profile.csv: per column, the surface at t = 0 and at the end, and their
//   difference. crater_depth_m: the largest drop; crater_radius_m: half the width of the
//   connected columns around it that dropped by more than the largest grain radius;
//   crater_radius_lower_bound = 1 when those columns reach a side of the domain (the radius is
//   then the domain's, a lower bound), else 0;
//   surface_settlement_max_m (and _x_m): the largest drop of the other columns, outside the
//   crater and the column next to it (negative: they all rose).
//   3D: the surface averaged in rings about the crater's axis (probes.axis_m, else the first
//   detonation point of the first SPH part that has one, else the full model's horizontal
//   centre: config.hpp). Ring j holds the columns whose centres lie at j w <= r < (j + 1) w from
//   the axis (w the column width), its value the mean over those with a surface at both times.
//   With vertical planes of symmetry through the axis (a quarter model: the axis at the
//   corner) the modelled columns of a ring are mirror images of the rest: their mean is the
//   full model's. surface_profile.csv: per ring, r_m (its columns' mean distance),
//   surface_initial_m, surface_m, dz_m. crater_depth_m: the largest drop of a ring (0 when not
//   above the largest grain radius); crater_radius_m: going outward from that ring (the axis
//   ring of a bowl), the radius at which the drop first falls below the largest grain radius,
//   linear between the rings (the last ring's radius when it never does: then
//   crater_radius_lower_bound = 1, the radius is the domain's, a lower bound; else 0);
//   surface_settlement_max_m (and _r_m): the largest drop of the rings outside the crater and
//   the ring next to it (r > crater_radius_m + w); crater_axis_x_m, _y_m: the axis used.
// Plate. plate_peak_von_mises_pa: the largest von Mises stress over the live elements at the
// end of the first step reaching probes.stress_time_s (plate_peak_von_mises_time_s says when);
// plate_peak_von_mises_max_pa: the largest over the history rows (and that sample);
// plate_eroded_elements; plate_perforated = 1 when eroded elements sharing nodes connect the
// plate's bottom face to its top face (faces of the undeformed plate along the vertical axis).
// plate_perforated_area_m2: the area of the plate's undeformed horizontal footprint where a
// vertical line meets only eroded elements: the footprints (the nodes' positions at t = 0)
// of the element columns through the thickness all of whose elements are eroded
// (probe_geometry.hpp), the full model's: x 2 per vertical plane of symmetry. In 2D the
// perforated length x 1 m (per metre of depth).
// delamination_gap_max_m: per column, the open gap between the plate's live nodes and the
// nearest grain under the plate, and over it where the ground still covers it (its surface a
// cell above the plate); the largest over the columns. At t = 0 it is the packing's own gap at
// the plate's faces (up to about a grain radius).
// The vertical axis is the last one (y in 2D, z in 3D).
// Tunnel lining: lining_probe.hpp.
#pragma once

#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "io/scenario/config.hpp"
#include "parallel/comm.hpp"
#include "solver/lining_probe.hpp"
#include "solver/part_names.hpp"

namespace crater::solver {

template <int D>
class Probes {
 public:
  /// Measures the initial ground surface from the parts' state at t = 0.
  Probes(const io::Config& config, const std::vector<std::unique_ptr<Part<D>>>& parts);

  bool empty() const { return !cfg_.any(); }

  /// history.csv: the plate's largest von Mises stress (plate_max_von_mises_pa).
  std::vector<std::string> history_columns() const;
  /// The values for a history row at time t (also the running maximum). `spread`: the ranks
  /// the parts are spread over (null on one rank); the plate's largest stress is then the
  /// largest of every rank's own elements (collective).
  std::vector<Real> history_values(const std::vector<std::unique_ptr<Part<D>>>& parts,
                                   const parallel::Comm* spread = nullptr);

  /// After each step: samples the plate at probes.stress_time_s (collective on ranks, as
  /// history_values).
  void after_step(const std::vector<std::unique_ptr<Part<D>>>& parts, Real t_s,
                  const parallel::Comm* spread = nullptr);

  /// The metrics of the current state (summary.json), and surface_profile.csv into `dir`.
  /// `spread`: the ranks the parts are spread over (null on one rank). Collective then: each
  /// rank reads the entities it owns, and the root gets the sums over the ranks
  /// (reproducible) and writes; its metrics are the run's. No part is gathered whole.
  std::vector<Diagnostic> finish(const std::vector<std::unique_ptr<Part<D>>>& parts,
                                 const std::filesystem::path& dir,
                                 const parallel::Comm* spread = nullptr) const;

  void save(parts::StateWriter& w) const;
  void load(parts::StateReader& r);

 private:
  struct Column {
    std::vector<Real> filled;   // F per cell, bottom up [m^D]
    std::vector<Index> grains;  // grains per cell
  };
  // The ground's cells in the current state (columns in row-major order of their indices), on
  // the root (empty elsewhere): each cell's F a reproducible sum of its terms over the ranks,
  // each rank adding its own grains and elements. `with_plate`: the plate's live elements
  // count too (not for the packing fraction).
  std::vector<Column> ground(const std::vector<std::unique_ptr<Part<D>>>& parts,
                             const parallel::Comm& comm, bool with_plate = true) const;
  bool airborne(Real contacts, const Real* v, Real r) const;
  void plate_metrics(const std::vector<std::unique_ptr<Part<D>>>& parts, const parallel::Comm& comm,
                     std::vector<Diagnostic>& m) const;
  void ground_metrics(const std::vector<std::unique_ptr<Part<D>>>& parts,
                      const parallel::Comm& comm, const std::filesystem::path& dir,
                      std::vector<Diagnostic>& m) const;
  // The profile, crater and settlement from the columns' surfaces at t = 0 and now: per
  // column (2D), in rings about the crater's axis (3D).
  void column_crater_metrics(const std::vector<Real>& now, const std::vector<Real>& drop,
                             const std::filesystem::path& dir, std::vector<Diagnostic>& m) const;
  void ring_crater_metrics(const std::vector<Real>& now, const std::filesystem::path& dir,
                           std::vector<Diagnostic>& m) const;
  void gap_metrics(const std::vector<std::unique_ptr<Part<D>>>& parts, const parallel::Comm& comm,
                   const std::vector<Real>& now, std::vector<Diagnostic>& m) const;
  Real column_centre(std::size_t k, int axis) const;
  // The ground's surface in column k (NaN: no ground), see the file comment.
  Real surface_height(const Column& col, std::size_t k) const;
  // The column holding x (its horizontal coordinates); false outside the domain.
  bool column_of(const Vec<D>& x, Index& col) const;
  // The ground cell holding x (column * rows_ + row); false outside the domain.
  bool cell_of(const Vec<D>& x, std::int64_t& cell) const;
  // f(i, cell, x, r) for each grain of the ground's cells: the soil's grains this rank owns
  // (every one on one rank) inside the domain and not in free flight.
  template <class F>
  void for_each_ground_grain(const Part<D>& soil, F&& f) const;
  // f(q) for each column q next to column k along a horizontal axis.
  template <class F>
  void for_each_neighbour(std::size_t k, F&& f) const;
  Real plate_max_von_mises(const std::vector<std::unique_ptr<Part<D>>>& parts,
                           const parallel::Comm* spread = nullptr) const;
  Real cell_volume_ground() const {
    Real v = bin_;
    for (int d = 0; d + 1 < D; ++d)
      v *= width_[d];
    return v;
  }

  io::ProbesConfig cfg_;
  Vec<D> lo_ = Vec<D>::Zero();  // domain's lower corner
  Real bin_ = 0;
  Index columns_[D - 1] = {};
  Real width_[D - 1] = {};  // column widths: the domain's width over the column count
  Index rows_ = 0;
  Real grain_r_max_ = 0;
  Real phi_ref_ = 1;
  Real gravity_ = 0;  // |g| along the vertical axis [m/s^2]
  // 2 per vertical plane of symmetry: what a horizontal measure of the modelled part is
  // multiplied by for the full model's.
  Real mirror_factor_ = 1;
  std::array<bool, 2> mirror_side_{};  // 2D: the low / high x side is a plane of symmetry
  std::vector<Real> surface0_;         // per column; NaN where there is no ground
  // Per column, per cell: it reaches into a region the soil was laid around (the charge's,
  // the plate's), where a column's ground may have a gap.
  std::vector<std::vector<char>> hole_;
  Index gap_cells_ = 0;  // the longest gap in a column's ground, in cells
  // Plate samples.
  Real peak_at_time_ = -1, peak_time_s_ = -1, peak_max_ = 0;
  // The plate's mesh at t = 0 (its nodes' reference positions, its cells as VTK lists them),
  // whole: where the eroded elements its ranks own are placed for erosion and perforation.
  std::vector<Vec<D>> plate_x0_;
  std::vector<std::int64_t> plate_connectivity_, plate_offsets_;
  // A tunnel's lining ([probes] lining), when measured.
  std::unique_ptr<LiningProbe<D>> lining_;
};

}  // namespace crater::solver
