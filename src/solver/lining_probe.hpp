// A tunnel lining's measurements ([probes] lining; docs/theory.md "Probes"): the radial
// displacement of its inner wall at the crown, springline and invert, its damage and erosion.
//
// The tunnel's axis is a line (probes.lining_axis_point_m, along probes.lining_axis_direction in
// 3D; in 2D perpendicular to the plane through the point). The gauges sit in the cross-section
// through the axis point: of the lining's nodes nearest that section (at t = 0; 2D: all), those
// on the inner wall (within 1e-3 of the smallest distance from the axis), the crown being the
// highest, the invert the lowest and the springline the one furthest across (the last axis is
// vertical; across: the horizontal direction perpendicular to the axis, the side the model
// has, +x when it has both). A gauge's value is the node's displacement along its outward
// radial direction at t = 0 (positive: the wall moves away from the axis).
//
// history.csv: lining_crown_radial_m, lining_springline_radial_m, lining_invert_radial_m.
// summary.json: lining_crown_displacement_max_m (the largest outward radial displacement of the
// crown over the steps; the paper's "maximum radial deformation at the crown"),
// lining_crown_displacement_min_m (the largest inward, negative), the same for springline and
// invert, lining_damage_max (over the live elements), lining_damaged_volume_m3 (the volume at
// t = 0 of the elements whose damage is at least 0.5, eroded ones included, the full model's:
// x 2 per plane of symmetry of the domain) and lining_eroded_elements (of the model).
//
// With probes.lining_soil, the soil along the crown line: its nodes (at t = 0) on the vertical
// through the crown gauge's node, above it, within 1e-3 of the inner radius (none: exit 2).
// Per node, the upward displacement's extremes over the steps; crown_line.csv at the end;
// history.csv soil_crown_line_interface_up_m and _surface_up_m (the lowest and the highest
// node); summary.json soil_crown_line_{interface,surface}_displacement_{max,min}_m.
#pragma once

#include <array>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "io/scenario/config.hpp"
#include "parallel/comm.hpp"
#include "solver/part_names.hpp"

namespace crater::solver {

template <int D>
class LiningProbe {
 public:
  /// Finds the gauges' nodes from the lining's state at t = 0.
  LiningProbe(const io::Config& config, const std::vector<std::unique_ptr<Part<D>>>& parts);

  std::vector<std::string> history_columns() const;
  std::vector<Real> history_values(const std::vector<std::unique_ptr<Part<D>>>& parts) const;
  /// Every rank calls history_values, after_step and metrics (collective on ranks); the finder
  /// reads the parts whole (at t = 0, before they are spread).
  /// After each step: the gauges' extremes.
  void after_step(const std::vector<std::unique_ptr<Part<D>>>& parts);
  /// Into m, and crown_line.csv into dir (with lining_soil). `spread`: the ranks the parts are
  /// spread over (null on one rank); each reads the elements it owns, and the root, which
  /// writes, gets the numbers of the damaged ones and the extremes over the ranks.
  void metrics(const std::vector<std::unique_ptr<Part<D>>>& parts, const std::filesystem::path& dir,
               std::vector<Diagnostic>& m, const parallel::Comm* spread = nullptr) const;

  void save(parts::StateWriter& w) const;
  void load(parts::StateReader& r);

 private:
  static constexpr int kGauges = 3;  // crown, springline, invert
  // The gauges' nodes (none where a gauge has no node) and the crown line's nodes, now. The
  // nodes alone, not the parts' displacement fields: this runs every step. Collective on ranks
  // (Part::points_numbered: the parts are spread, the numbers are one rank's).
  struct Now {
    std::array<std::optional<Vec<D>>, kGauges> gauge;
    std::vector<Vec<D>> line;
  };
  Now now(const std::vector<std::unique_ptr<Part<D>>>& parts) const;
  // Gauge g's radial displacement in `n` (NaN: no node).
  Real radial(const Now& n, int g) const;
  // The soil's nodes on the crown line, from the crown gauge's position at t = 0 (c0).
  void find_crown_line(const io::Config& c, const Part<D>& soil, const Vec<D>& c0, Real r_in);

  std::size_t part_ = 0;
  Real mirror_factor_ = 1;
  std::array<Index, kGauges> node_{-1, -1, -1};
  std::array<Vec<D>, kGauges> outward_{};
  std::array<Vec<D>, kGauges> x0_{};  // the gauge nodes' positions at t = 0
  std::array<Real, kGauges> max_{}, min_{};
  std::vector<Real> volume0_;  // per element, at t = 0
  // Crown line (lining_soil): the soil's nodes from the lining up, their positions at t = 0
  // and their upward displacement's extremes.
  std::optional<std::size_t> soil_;
  std::vector<Index> line_node_;
  std::vector<Vec<D>> line_x0_;
  std::vector<Real> line_max_, line_min_;
};

}  // namespace crater::solver
