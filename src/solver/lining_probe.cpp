// A tunnel lining's measurements; see lining_probe.hpp.
#include "solver/lining_probe.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string_view>

#include "core/error.hpp"
#include "core/index.hpp"
#include "fem/element_geometry.hpp"
#include "io/checkpoint/checkpoint.hpp"
#include "io/output/atomic_file.hpp"

namespace crater::solver {
namespace {

constexpr Real kNaN = std::numeric_limits<Real>::quiet_NaN();
constexpr std::array<const char*, 3> kGaugeNames{"crown", "springline", "invert"};

}  // namespace

template <int D>
LiningProbe<D>::LiningProbe(const io::Config& c, const std::vector<std::unique_ptr<Part<D>>>& parts)
    : part_(*c.probes.lining), soil_(c.probes.lining_soil) {
  for (const parts::Face f : c.domain.symmetry_planes) {
    (void)f;
    mirror_factor_ *= 2;
  }
  max_.fill(0);
  min_.fill(0);
  const Part<D>& lining = *parts[part_];
  const Geometry<D> g = lining.geometry();
  const auto disp_views = lining.point_fields();  // the views disp points into
  const auto* disp = fields::find_field(disp_views, "displacement");
  const auto& xn = *g.points;
  const Index nn = static_cast<Index>(xn.size());
  auto ref = [&](Index i) {
    Vec<D> x = xn[at(i)];
    if (disp)
      for (int d = 0; d < D; ++d)
        x[d] -= disp->real_data[at(i) * D + static_cast<std::size_t>(d)];
    return x;
  };
  Vec<D> p = Vec<D>::Zero(), axis = Vec<D>::Zero();
  for (int d = 0; d < D; ++d)
    p[d] = c.probes.lining_axis_point_m[static_cast<std::size_t>(d)];
  if constexpr (D == 3)
    for (int d = 0; d < 3; ++d)
      axis[d] = c.probes.lining_axis_direction[static_cast<std::size_t>(d)];
  if (axis.norm() > 0) axis.normalize();
  // Per node: its offset from the axis (perpendicular) and its distance along it.
  std::vector<Vec<D>> off(at(nn));
  std::vector<Real> along(at(nn), 0);
  Real nearest_section = std::numeric_limits<Real>::infinity();
  for (Index i = 0; i < nn; ++i) {
    const Vec<D> r = ref(i) - p;
    along[at(i)] = r.dot(axis);
    off[at(i)] = r - along[at(i)] * axis;
    nearest_section = std::min(nearest_section, std::abs(along[at(i)]));
  }
  Real r_in = std::numeric_limits<Real>::infinity(), extent = 0;
  for (Index i = 0; i < nn; ++i) {
    extent = std::max(extent, off[at(i)].norm());
    if (std::abs(along[at(i)]) <= nearest_section + 1e-9 * (1 + extent))
      r_in = std::min(r_in, off[at(i)].norm());
  }
  // Across: the horizontal direction perpendicular to the axis, towards the side the model has.
  Vec<D> up = Vec<D>::Zero();
  up[D - 1] = 1;
  Vec<D> across = Vec<D>::Zero();
  if constexpr (D == 3) {
    across = axis.cross(up);
  } else {
    across[0] = 1;
  }
  if (across.norm() > 0) across.normalize();
  Real most = 0, least = 0;
  for (Index i = 0; i < nn; ++i) {
    const Real s = off[at(i)].dot(across);
    most = std::max(most, s);
    least = std::min(least, s);
  }
  if (most < -least) across = -across;
  std::array<Real, kGauges> score;
  score.fill(-std::numeric_limits<Real>::infinity());
  for (Index i = 0; i < nn; ++i) {
    if (std::abs(along[at(i)]) > nearest_section + 1e-9 * (1 + extent)) continue;
    if (off[at(i)].norm() > r_in * (1 + 1e-3)) continue;
    const std::array<Real, kGauges> s{off[at(i)].dot(up), off[at(i)].dot(across),
                                      -off[at(i)].dot(up)};
    for (int k = 0; k < kGauges; ++k)
      if (s[at(k)] > score[at(k)]) {
        score[at(k)] = s[at(k)];
        node_[at(k)] = i;
      }
  }
  for (int k = 0; k < kGauges; ++k)
    if (node_[at(k)] >= 0) {
      const Vec<D>& o = off[at(node_[at(k)])];
      outward_[at(k)] = o.norm() > 0 ? Vec<D>(o / o.norm()) : Vec<D>::Zero();
      x0_[at(k)] = ref(node_[at(k)]);
    }
  if (soil_ && node_[0] >= 0) find_crown_line(c, *parts[*soil_], x0_[0], r_in);
  // Element volumes at t = 0.
  const Index ne = static_cast<Index>(g.offsets.size());
  volume0_.assign(at(ne), 0);
  for (Index e = 0; e < ne; ++e) {
    const std::int64_t first = e == 0 ? 0 : g.offsets[at(e - 1)];
    if (g.offsets[at(e)] - first != fem::kElementNodes<D>) continue;
    fem::NodeArray<D> xe;
    for (int k = 0; k < fem::kElementNodes<D>; ++k)
      xe[at(k)] = ref(static_cast<Index>(g.connectivity[at(first + k)]));
    volume0_[at(e)] = std::max(Real(0), fem::uniform_strain_gradients<D>(xe).volume);
  }
}

template <int D>
void LiningProbe<D>::find_crown_line(const io::Config& c, const Part<D>& soil, const Vec<D>& c0,
                                     Real r_in) {
  const auto disp_views = soil.point_fields();  // the views disp points into
  const auto* disp = fields::find_field(disp_views, "displacement");
  const auto& xn = soil.points();
  const Real tol = Real(1e-3) * r_in;
  std::vector<std::pair<Real, Index>> found;  // (height above the crown, node)
  for (Index i = 0; i < static_cast<Index>(xn.size()); ++i) {
    Vec<D> r = xn[at(i)] - c0;
    if (disp)
      for (int d = 0; d < D; ++d)
        r[d] -= disp->real_data[at(i) * D + static_cast<std::size_t>(d)];
    const Real h = r[D - 1];
    r[D - 1] = 0;
    if (h >= -tol && r.norm() <= tol) found.emplace_back(h, i);
  }
  if (found.empty())
    throw InputError({c.file, 0, 0}, "probes.lining_soil",
                     fmt::format("part '{}' has no node on the crown line (the vertical through "
                                 "the lining's crown gauge, above it, within {:g} m): its mesh "
                                 "needs a column of nodes there",
                                 soil.name(), tol));
  std::sort(found.begin(), found.end());
  for (const auto& [h, i] : found) {
    line_node_.push_back(i);
    Vec<D> x = xn[at(i)];
    if (disp)
      for (int d = 0; d < D; ++d)
        x[d] -= disp->real_data[at(i) * D + static_cast<std::size_t>(d)];
    line_x0_.push_back(x);
  }
  line_max_.assign(line_node_.size(), 0);
  line_min_.assign(line_node_.size(), 0);
}

// The gauges' nodes (those found) and the crown line's, where they are now: one read of each
// part, collective on ranks (every rank calls it at the same point of the run).
template <int D>
typename LiningProbe<D>::Now LiningProbe<D>::now(
    const std::vector<std::unique_ptr<Part<D>>>& parts) const {
  Now n;
  std::vector<Index> found;
  for (const Index i : node_)
    if (i >= 0) found.push_back(i);
  const std::vector<Vec<D>> x = parts[part_]->points_numbered(found);
  std::size_t k = 0;
  for (int g = 0; g < kGauges; ++g)
    n.gauge[at(g)] = node_[at(g)] >= 0 ? std::optional<Vec<D>>(x[k++]) : std::nullopt;
  if (!line_node_.empty()) n.line = parts[*soil_]->points_numbered(line_node_);
  return n;
}

template <int D>
Real LiningProbe<D>::radial(const Now& n, int g) const {
  if (!n.gauge[at(g)]) return kNaN;
  const Vec<D> u = *n.gauge[at(g)] - x0_[at(g)];
  Real r = 0;
  for (int d = 0; d < D; ++d)
    r += u[d] * outward_[at(g)][d];
  return r;
}

template <int D>
std::vector<std::string> LiningProbe<D>::history_columns() const {
  std::vector<std::string> out;
  for (const char* n : kGaugeNames)
    out.push_back(fmt::format("lining_{}_radial_m", n));
  if (!line_node_.empty()) {
    out.emplace_back("soil_crown_line_interface_up_m");
    out.emplace_back("soil_crown_line_surface_up_m");
  }
  return out;
}

template <int D>
std::vector<Real> LiningProbe<D>::history_values(
    const std::vector<std::unique_ptr<Part<D>>>& parts) const {
  const Now n = now(parts);
  std::vector<Real> out;
  for (int g = 0; g < kGauges; ++g)
    out.push_back(radial(n, g));
  if (!line_node_.empty())
    for (const std::size_t k : {std::size_t{0}, line_node_.size() - 1})
      out.push_back(n.line[k][D - 1] - line_x0_[k][D - 1]);
  return out;
}

template <int D>
void LiningProbe<D>::after_step(const std::vector<std::unique_ptr<Part<D>>>& parts) {
  const Now n = now(parts);
  for (int g = 0; g < kGauges; ++g) {
    const Real u = radial(n, g);
    if (!std::isfinite(u)) continue;
    max_[at(g)] = std::max(max_[at(g)], u);
    min_[at(g)] = std::min(min_[at(g)], u);
  }
  for (std::size_t k = 0; k < line_node_.size(); ++k) {
    const Real up = n.line[k][D - 1] - line_x0_[k][D - 1];
    line_max_[k] = std::max(line_max_[k], up);
    line_min_[k] = std::min(line_min_[k], up);
  }
}

template <int D>
void LiningProbe<D>::metrics(const std::vector<std::unique_ptr<Part<D>>>& parts,
                             const std::filesystem::path& dir, std::vector<Diagnostic>& m,
                             const parallel::Comm* spread) const {
  // Each rank's own elements (all on one rank): the largest damage of the live ones, the eroded
  // count, and the numbers of the damaged or eroded, whose volumes at t = 0 the root adds in
  // element order.
  const auto numbers = parts[part_]->own_numbers();
  const auto cf = parts[part_]->cell_fields();
  const auto* damage = fields::find_field(cf, "damage");
  const auto* eroded = fields::find_field(cf, "eroded");
  Real dmax = 0;
  std::int64_t eroded_count = 0;
  std::vector<std::int64_t> damaged_here;
  const Index cells = damage ? damage->size : eroded ? eroded->size : 0;
  for (Index e = 0; e < cells; ++e) {
    const std::int64_t number = numbers ? numbers->cell[at(e)] : e;
    if (number < 0) continue;  // a ghost: another rank's
    const bool gone = eroded && eroded->integer_data[e] != 0;
    eroded_count += gone ? 1 : 0;
    const Real d = damage ? damage->real_data[e] : 0;
    if (!gone) dmax = std::max(dmax, d);
    if (d >= Real(0.5) || gone) damaged_here.push_back(number);
  }
  std::vector<std::int64_t> damaged_numbers = damaged_here;
  if (spread) {
    dmax = spread->max(dmax);
    eroded_count = spread->sum(eroded_count);
    damaged_numbers = parallel::gather(*spread, std::span<const std::int64_t>(damaged_here));
  }
  // The crown line's nodes now, from their owners (collective).
  const std::vector<Vec<D>> line =
      line_node_.empty() ? std::vector<Vec<D>>{} : parts[*soil_]->points_numbered(line_node_);
  if (spread && !spread->root()) return;
  for (int g = 0; g < kGauges; ++g) {
    if (node_[at(g)] < 0) continue;
    m.push_back({fmt::format("lining_{}_displacement_max_m", kGaugeNames[at(g)]), max_[at(g)]});
    m.push_back({fmt::format("lining_{}_displacement_min_m", kGaugeNames[at(g)]), min_[at(g)]});
  }
  std::vector<std::uint8_t> damaged_flag(volume0_.size(), 0);
  for (const std::int64_t e : damaged_numbers)
    damaged_flag[at(e)] = 1;
  Real damaged = 0;
  for (std::size_t e = 0; e < volume0_.size(); ++e)
    if (damaged_flag[e]) damaged += volume0_[e];
  const std::array<Diagnostic, 3> whole{
      Diagnostic{"lining_damage_max", dmax},
      Diagnostic{"lining_damaged_volume_m3", damaged * mirror_factor_},
      Diagnostic{"lining_eroded_elements", static_cast<Real>(eroded_count)}};
  m.insert(m.end(), whole.begin(), whole.end());
  if (line_node_.empty()) return;
  const std::size_t last = line_node_.size() - 1;
  for (const auto& [name, k] : {std::pair<const char*, std::size_t>{"interface", 0},
                                std::pair<const char*, std::size_t>{"surface", last}}) {
    m.push_back({fmt::format("soil_crown_line_{}_displacement_max_m", name), line_max_[k]});
    m.push_back({fmt::format("soil_crown_line_{}_displacement_min_m", name), line_min_[k]});
  }
  std::string csv =
      "node,z_m,depth_m,above_crown_m,up_displacement_max_m,up_displacement_min_m,"
      "up_displacement_m\n";
  const Real top = line_x0_[last][D - 1];
  for (std::size_t k = 0; k <= last; ++k) {
    const Real z0 = line_x0_[k][D - 1];
    csv += fmt::format("{},{},{},{},{},{},{}\n", line_node_[k], z0, top - z0, z0 - x0_[0][D - 1],
                       line_max_[k], line_min_[k], line[k][D - 1] - z0);
  }
  io::write_file_atomic(dir / "crown_line.csv", csv);
}

template <int D>
void LiningProbe<D>::save(parts::StateWriter& w) const {
  w.tag("lining_probe");
  for (int g = 0; g < kGauges; ++g) {
    w.value(max_[at(g)]);
    w.value(min_[at(g)]);
  }
  for (std::size_t k = 0; k < line_node_.size(); ++k) {
    w.value(line_max_[k]);
    w.value(line_min_[k]);
  }
}

template <int D>
void LiningProbe<D>::load(parts::StateReader& r) {
  r.tag("lining_probe");
  for (int g = 0; g < kGauges; ++g) {
    r.value(max_[at(g)]);
    r.value(min_[at(g)]);
  }
  for (std::size_t k = 0; k < line_node_.size(); ++k) {
    r.value(line_max_[k]);
    r.value(line_min_[k]);
  }
}

template class LiningProbe<2>;
template class LiningProbe<3>;

}  // namespace crater::solver
