// The paper's measurements; see probes.hpp.
#include "solver/probes.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string_view>

#include "core/index.hpp"
#include "dem/packing.hpp"
#include "fem/element_geometry.hpp"
#include "io/checkpoint/checkpoint.hpp"
#include "io/output/atomic_file.hpp"
#include "solver/probe_geometry.hpp"

namespace crater::solver {
namespace {

constexpr Real kNaN = std::numeric_limits<Real>::quiet_NaN();

/// Whether cell e of a part's `eroded` field (none: nothing erodes) is eroded.
bool eroded_at(const fields::FieldView* eroded, std::size_t e) {
  return eroded && eroded->integer_data[e] != 0;
}

/// Volume of an FEM element (area per metre in 2D) from the writers' connectivity, which lists
/// the element's nodes in the mesh's order: the element's own one-point volume.
template <int D>
Real element_volume(const std::vector<Vec<D>>& x, const std::int64_t* nodes) {
  fem::NodeArray<D> xe;
  for (int k = 0; k < fem::kElementNodes<D>; ++k)
    xe[at(k)] = x[at(nodes[k])];
  return std::max(Real(0), fem::uniform_strain_gradients<D>(xe).volume);
}

// The indices 0..n-1 in ascending id (as they are without an id field).
std::vector<Index> in_id_order(const fields::FieldView* id, Index n) {
  std::vector<Index> order(at(n));
  std::iota(order.begin(), order.end(), Index{0});
  if (id && id->is_integer && id->size == n)
    std::stable_sort(order.begin(), order.end(), [&](Index a, Index b) {
      return id->integer_data[at(a)] < id->integer_data[at(b)];
    });
  return order;
}

}  // namespace

template <int D>
bool Probes<D>::column_of(const Vec<D>& x, Index& col) const {
  col = 0;
  for (int d = 0; d + 1 < D; ++d) {
    const Real f = std::floor((x[d] - lo_[d]) / width_[d]);
    if (!(f >= 0 && f < static_cast<Real>(columns_[d]))) return false;
    col = col * columns_[d] + static_cast<Index>(f);
  }
  return true;
}

template <int D>
template <class F>
void Probes<D>::for_each_neighbour(std::size_t k, F&& f) const {
  // Columns are numbered row-major, the last horizontal axis fastest.
  Index stride = 1;
  for (int d = D - 2; d >= 0; --d) {
    const Index i = (static_cast<Index>(k) / stride) % columns_[d];
    for (int s : {-1, 1})
      if (i + s >= 0 && i + s < columns_[d]) f(at(static_cast<Index>(k) + s * stride));
    stride *= columns_[d];
  }
}

template <int D>
Probes<D>::Probes(const io::Config& c, const std::vector<std::unique_ptr<Part<D>>>& parts)
    : cfg_(c.probes) {
  // A vertical plane of symmetry mirrors the modelled part into the other half: the full
  // model's horizontal area is twice the modelled one, whether a hole meets the plane (it is
  // doubled) or not (it has a twin).
  for (const parts::Face f : c.domain.symmetry_planes)
    if (static_cast<int>(f) / 2 != D - 1) {
      mirror_factor_ *= 2;
      if (static_cast<int>(f) / 2 == 0) mirror_side_[static_cast<std::size_t>(f) % 2] = true;
    }
  if (cfg_.lining) lining_ = std::make_unique<LiningProbe<D>>(c, parts);
  if (!cfg_.soil) return;
  for (int d = 0; d < D; ++d)
    lo_[d] = c.domain.min_m[d];
  gravity_ = std::abs(c.domain.gravity_m_s2[D - 1]);
  const auto& soil = *parts[*cfg_.soil];
  const auto pf = soil.point_fields();
  const auto* radius = fields::find_field(pf, "radius");
  const Index n = soil.count();
  for (Index i = 0; radius && i < n; ++i)
    grain_r_max_ = std::max(grain_r_max_, radius->real_data[i]);
  bin_ = cfg_.surface_bin_m ? *cfg_.surface_bin_m : 8 * grain_r_max_;
  if (!(bin_ > 0)) bin_ = 1;
  // At most ~1e7 cells: coarser columns for a huge domain.
  for (;;) {
    Real cells = 1;
    for (int d = 0; d < D; ++d)
      cells *= std::ceil((c.domain.max_m[d] - c.domain.min_m[d]) / bin_);
    if (cells <= 1e7) break;
    bin_ *= 2;
  }
  // Columns tile the domain's width exactly (no part-empty column at the far side).
  for (int d = 0; d + 1 < D; ++d) {
    const Real extent = c.domain.max_m[d] - c.domain.min_m[d];
    columns_[d] = std::max<Index>(1, static_cast<Index>(std::round(extent / bin_)));
    width_[d] = extent / static_cast<Real>(columns_[d]);
  }
  rows_ = std::max<Index>(
      1, static_cast<Index>(std::ceil((c.domain.max_m[D - 1] - c.domain.min_m[D - 1]) / bin_)));

  Index ncol = 1;
  for (int d = 0; d + 1 < D; ++d)
    ncol *= columns_[d];
  gap_cells_ = static_cast<Index>(std::floor(6 * grain_r_max_ / bin_));
  hole_.assign(at(ncol), std::vector<char>(at(rows_), 0));
  Real half_diagonal = bin_ * bin_;
  for (int d = 0; d + 1 < D; ++d)
    half_diagonal += width_[d] * width_[d];
  half_diagonal = Real(0.5) * std::sqrt(half_diagonal);
  const auto& carve = c.parts[*cfg_.soil].carve;
  for (std::size_t k = 0; k < at(ncol) && !carve.empty(); ++k)
    for (Index r = 0; r < rows_; ++r) {
      Vec<D> x;
      for (int d = 0; d + 1 < D; ++d)
        x[d] = column_centre(k, d);
      x[D - 1] = lo_[D - 1] + (static_cast<Real>(r) + Real(0.5)) * bin_;
      // A cell reaching into the region (its centre within half its diagonal of it): part of
      // it is the hole, so it may hold less than half a cell of soil.
      for (const std::size_t p : carve)
        if (parts::region_distance<D>(c.parts[p].region, x) < half_diagonal) hole_[k][at(r)] = 1;
    }

  // The bed's packing fraction: grains per cell volume, median over cells with grains in the
  // cells above and below (inside the bed).
  phi_ref_ = 1;
  {
    const auto cols = ground(parts);  // with phi_ref = 1: F = grain volume (+ plate)
    const Real cell = cell_volume_ground();
    std::vector<Real> inside;
    for (const auto& col : cols)
      for (std::size_t k = 1; k + 1 < col.grains.size(); ++k) {
        if (col.grains[k].empty() || col.grains[k - 1].empty() || col.grains[k + 1].empty())
          continue;
        Real v = 0;
        for (Index i : col.grains[k])
          v += dem::grain_volume<D>(radius->real_data[i]);
        inside.push_back(v / cell);
      }
    if (!inside.empty()) {
      std::nth_element(inside.begin(), inside.begin() + static_cast<long>(inside.size() / 2),
                       inside.end());
      phi_ref_ = std::clamp(inside[inside.size() / 2], Real(0.05), Real(1));
    }
  }
  const auto cols = ground(parts);
  surface0_.resize(cols.size());
  for (std::size_t k = 0; k < cols.size(); ++k)
    surface0_[k] = surface_height(cols[k], k);
}

template <int D>
std::vector<typename Probes<D>::Column> Probes<D>::ground(
    const std::vector<std::unique_ptr<Part<D>>>& parts) const {
  Index ncol = 1;
  for (int d = 0; d + 1 < D; ++d)
    ncol *= columns_[d];
  std::vector<Column> cols(at(ncol));
  for (auto& c : cols) {
    c.filled.assign(at(rows_), 0);
    c.grains.resize(at(rows_));
  }
  // Column and row of a point; false outside the domain.
  auto locate = [&](const Vec<D>& x, Index& col, Index& row) {
    if (!column_of(x, col)) return false;
    const Real f = std::floor((x[D - 1] - lo_[D - 1]) / bin_);
    if (!(f >= 0 && f < static_cast<Real>(rows_))) return false;
    row = static_cast<Index>(f);
    return true;
  };
  const auto& soil = *parts[*cfg_.soil];
  const auto pf = soil.point_fields();
  const auto* radius = fields::find_field(pf, "radius");
  const auto* contacts = fields::find_field(pf, "contacts");
  const auto* velocity = fields::find_field(pf, "velocity");
  const auto& xs = *soil.geometry().points;
  // The grains in the order of their ids, which is how the root of several ranks holds them
  // (gathered_part.hpp): every cell's sum has the same bits on any rank count.
  const std::vector<Index> by_id = in_id_order(fields::find_field(pf, "id"), soil.count());
  for (const Index i : by_id) {
    Index col = 0, row = 0;
    if (!locate(xs[at(i)], col, row)) continue;
    if (contacts && velocity &&
        airborne(contacts->real_data[i], &velocity->real_data[D * i], radius->real_data[i]))
      continue;
    cols[at(col)].filled[at(row)] += dem::grain_volume<D>(radius->real_data[i]) / phi_ref_;
    cols[at(col)].grains[at(row)].push_back(i);
  }
  if (cfg_.plate) {
    const auto& plate = *parts[*cfg_.plate];
    const Geometry<D> g = plate.geometry();
    const auto eroded_views = plate.cell_fields();  // the views eroded points into
    const auto* eroded = fields::find_field(eroded_views, "eroded");
    const auto& xn = *g.points;
    std::int64_t begin = 0;
    for (std::size_t e = 0; e < g.offsets.size(); ++e) {
      const std::int64_t end = g.offsets[e];
      if (!eroded_at(eroded, e)) {
        Vec<D> centre = Vec<D>::Zero();
        for (std::int64_t k = begin; k < end; ++k)
          centre += xn[at(g.connectivity[at(k)])];
        centre /= static_cast<Real>(end - begin);
        Index col = 0, row = 0;
        // Only where the plate was laid (cells reaching into the soil's holes): a piece torn
        // off and thrown up is not the ground.
        if (locate(centre, col, row) && hole_[at(col)][at(row)])
          cols[at(col)].filled[at(row)] += element_volume<D>(xn, &g.connectivity[at(begin)]);
      }
      begin = end;
    }
  }
  return cols;
}

// A grain in free flight: it touches nothing and moves fast enough to rise more than its own
// diameter, |v| > sqrt(2 g 2r) (a grain merely resting without a contact, on an exact lattice or
// between two impacts on the ground, is not). Ejecta thrown up in a dense stream fill the
// probe's cells without a gap; this keeps them out of the ground.
template <int D>
bool Probes<D>::airborne(Real contacts, const Real* v, Real r) const {
  if (contacts > 0) return false;
  Real v2 = 0;
  for (int d = 0; d < D; ++d)
    v2 += v[d] * v[d];
  return v2 > 4 * gravity_ * r;
}

template <int D>
Real Probes<D>::surface_height(const Column& col, std::size_t column) const {
  const Real full = cell_volume_ground();
  const Index n = static_cast<Index>(col.filled.size());
  Index top = -1, gap = 0;
  for (Index k = 0; k < n; ++k) {
    const Real below = k > 0 ? col.filled[at(k - 1)] : full;
    if (col.filled[at(k)] > 0 && col.filled[at(k)] + below >= full / 2) {
      top = k;
      gap = 0;
    } else if (top >= 0 && !hole_[column][at(k)] && ++gap > gap_cells_) {
      break;  // what stands above is in flight
    }
  }
  if (top < 0) return kNaN;
  // The soil of the top cell and the one above, spread over the column, on that of the cell
  // below (as much of it as there is: a top cell's few grains over a half-empty cell below
  // are not a full cell of ground under them).
  const Real above = top + 1 < n ? col.filled[at(top + 1)] : 0;
  const Real below = top > 0 ? std::min(col.filled[at(top - 1)], full) : full;
  return lo_[D - 1] + static_cast<Real>(top - 1) * bin_ +
         (below + col.filled[at(top)] + above) / (full / bin_);
}

template <int D>
Real Probes<D>::plate_max_von_mises(const std::vector<std::unique_ptr<Part<D>>>& parts,
                                    const parallel::Comm* spread) const {
  const auto cf = parts[*cfg_.plate]->cell_fields();
  const auto* vm = fields::find_field(cf, "von_mises");
  const auto* eroded = fields::find_field(cf, "eroded");
  Real m = 0;
  for (Index e = 0; vm && e < vm->size; ++e)
    if (!eroded_at(eroded, at(e))) m = std::max(m, vm->real_data[e]);
  // On ranks each holds its own elements and those around its own nodes, with the same bits
  // as one rank: the largest over the ranks is the whole plate's (a maximum is exact).
  return spread ? spread->max(m) : m;
}

template <int D>
std::vector<std::string> Probes<D>::history_columns() const {
  std::vector<std::string> out;
  if (cfg_.plate) out.push_back("plate_max_von_mises_pa");
  if (lining_)
    for (std::string& n : lining_->history_columns())
      out.push_back(std::move(n));
  return out;
}

template <int D>
std::vector<Real> Probes<D>::history_values(const std::vector<std::unique_ptr<Part<D>>>& parts,
                                            const parallel::Comm* spread) {
  std::vector<Real> out;
  if (cfg_.plate) {
    const Real m = plate_max_von_mises(parts, spread);
    peak_max_ = std::max(peak_max_, m);
    out.push_back(m);
  }
  if (lining_)
    for (const Real v : lining_->history_values(parts))
      out.push_back(v);
  return out;
}

template <int D>
void Probes<D>::after_step(const std::vector<std::unique_ptr<Part<D>>>& parts, Real t_s,
                           const parallel::Comm* spread) {
  if (lining_) lining_->after_step(parts);
  if (!cfg_.plate || peak_time_s_ >= 0 || t_s < cfg_.stress_time_s) return;
  peak_at_time_ = plate_max_von_mises(parts, spread);
  peak_time_s_ = t_s;
  peak_max_ = std::max(peak_max_, peak_at_time_);
}

template <int D>
std::vector<std::size_t> Probes<D>::read_at_finish() const {
  std::vector<std::size_t> k;
  if (cfg_.plate) k.push_back(*cfg_.plate);
  if (cfg_.soil) k.push_back(*cfg_.soil);
  if (lining_) k.push_back(*cfg_.lining);
  if (lining_ && cfg_.lining_soil) k.push_back(*cfg_.lining_soil);
  return k;
}

template <int D>
std::vector<Diagnostic> Probes<D>::finish(const std::vector<std::unique_ptr<Part<D>>>& parts,
                                          const std::filesystem::path& dir) const {
  std::vector<Diagnostic> m;
  if (cfg_.plate) plate_metrics(parts, m);
  if (cfg_.soil) ground_metrics(parts, dir, m);
  if (lining_) lining_->metrics(parts, dir, m);
  return m;
}

// The plate's peak stresses, its eroded elements, and whether eroded elements sharing nodes
// connect its bottom face to its top face (perforation).
template <int D>
void Probes<D>::plate_metrics(const std::vector<std::unique_ptr<Part<D>>>& parts,
                              std::vector<Diagnostic>& m) const {
  const auto& plate = *parts[*cfg_.plate];
  if (peak_time_s_ >= 0) {
    m.push_back({"plate_peak_von_mises_pa", peak_at_time_});
    m.push_back({"plate_peak_von_mises_time_s", peak_time_s_});
  }
  m.push_back({"plate_peak_von_mises_max_pa", std::max(peak_max_, plate_max_von_mises(parts))});
  // Erosion and perforation: eroded elements sharing nodes, from bottom face to top face.
  const Geometry<D> g = plate.geometry();
  const auto cf = plate.cell_fields();
  const auto* eroded = fields::find_field(cf, "eroded");
  const auto disp_views = plate.point_fields();  // the views disp points into
  const auto* disp = fields::find_field(disp_views, "displacement");
  const auto& xn = *g.points;
  const Index ne = static_cast<Index>(g.offsets.size());
  auto first = [&](Index e) { return e == 0 ? std::int64_t{0} : g.offsets[at(e - 1)]; };
  auto ref_up = [&](std::int64_t node) {
    Real z = xn[at(node)][D - 1];
    if (disp) z -= disp->real_data[at(node) * D + D - 1];
    return z;
  };
  Real zmin = std::numeric_limits<Real>::infinity(), zmax = -zmin;
  for (std::size_t k = 0; k < xn.size(); ++k) {
    zmin = std::min(zmin, ref_up(static_cast<std::int64_t>(k)));
    zmax = std::max(zmax, ref_up(static_cast<std::int64_t>(k)));
  }
  const Real tol = 1e-6 * std::max(Real(1e-3), zmax - zmin);
  Index eroded_count = 0;
  // Union-find over eroded elements through shared nodes.
  std::vector<Index> parent(at(ne));
  for (Index e = 0; e < ne; ++e)
    parent[at(e)] = e;
  auto find = [&](Index e) {
    while (parent[at(e)] != e)
      e = parent[at(e)] = parent[at(parent[at(e)])];
    return e;
  };
  std::vector<Index> node_owner(xn.size(), -1);
  auto is_eroded = [&](Index e) { return eroded_at(eroded, at(e)); };
  for (Index e = 0; e < ne; ++e) {
    if (!is_eroded(e)) continue;
    ++eroded_count;
    for (std::int64_t k = first(e); k < g.offsets[at(e)]; ++k) {
      const auto node = at(g.connectivity[at(k)]);
      if (node_owner[node] < 0)
        node_owner[node] = e;
      else
        parent[at(find(e))] = find(node_owner[node]);
    }
  }
  std::vector<std::uint8_t> bottom(at(ne), 0), top(at(ne), 0);
  bool perforated = false;
  for (Index e = 0; e < ne; ++e) {
    if (!is_eroded(e)) continue;
    const Index root = find(e);
    for (std::int64_t k = first(e); k < g.offsets[at(e)]; ++k) {
      const Real z = ref_up(g.connectivity[at(k)]);
      if (z <= zmin + tol) bottom[at(root)] = 1;
      if (z >= zmax - tol) top[at(root)] = 1;
    }
  }
  for (Index e = 0; e < ne; ++e)
    perforated = perforated || (bottom[at(e)] && top[at(e)]);
  m.push_back({"plate_eroded_elements", static_cast<Real>(eroded_count)});
  m.push_back({"plate_perforated", perforated ? Real(1) : Real(0)});
  // The undeformed footprint that only eroded elements cover, the full model's (mirrored in
  // the vertical symmetry planes); in 2D a length, x 1 m of depth.
  std::vector<Vec<D>> reference(xn.size());
  for (std::size_t k = 0; k < xn.size(); ++k) {
    reference[k] = xn[k];
    for (int d = 0; disp && d < D; ++d)
      reference[k][d] -= disp->real_data[k * D + at(d)];
  }
  std::vector<std::uint8_t> gone(at(ne));
  for (Index e = 0; e < ne; ++e)
    gone[at(e)] = is_eroded(e) ? 1 : 0;
  const Real area =
      perforated_footprint<D>({reference, g.connectivity, g.offsets, gone}) * mirror_factor_;
  m.push_back({"plate_perforated_area_m2", area});
}

// Column k's centre along horizontal axis `axis` (row-major: the last horizontal axis varies
// fastest).
template <int D>
Real Probes<D>::column_centre(std::size_t k, int axis) const {
  Index rest = static_cast<Index>(k);
  Index idx = 0;
  for (int d = D - 2; d >= 0; --d) {
    const Index i = rest % columns_[d];
    rest /= columns_[d];
    if (d == axis) idx = i;
  }
  return lo_[axis] + (static_cast<Real>(idx) + 0.5) * width_[axis];
}

// The ground surface now against t = 0 (surface_profile.csv), the crater, the settlement
// around it and, with a plate, the plate-soil gaps.
template <int D>
void Probes<D>::ground_metrics(const std::vector<std::unique_ptr<Part<D>>>& parts,
                               const std::filesystem::path& dir, std::vector<Diagnostic>& m) const {
  // Ground surface now and at t = 0.
  const auto cols = ground(parts);
  const std::size_t nc = cols.size();
  std::vector<Real> now(nc), drop(nc, kNaN);
  for (std::size_t k = 0; k < nc; ++k) {
    now[k] = surface_height(cols[k], k);
    // A column that had ground and has none left (the blast emptied it, or it left through
    // the model's faces) is a hole down to the domain's bottom, not "no data": it belongs to
    // the crater.
    if (!std::isfinite(now[k]) && std::isfinite(surface0_[k])) now[k] = lo_[D - 1];
    if (std::isfinite(now[k]) && std::isfinite(surface0_[k])) drop[k] = surface0_[k] - now[k];
  }
  if constexpr (D == 2)
    column_crater_metrics(now, drop, dir, m);
  else
    ring_crater_metrics(now, dir, m);
  if (cfg_.plate) gap_metrics(parts, cols, now, m);
}

// 2D: the profile per column, the crater as the connected columns around the deepest one, the
// settlement of the others.
template <int D>
void Probes<D>::column_crater_metrics(const std::vector<Real>& now, const std::vector<Real>& drop,
                                      const std::filesystem::path& dir,
                                      std::vector<Diagnostic>& m) const {
  const std::size_t nc = now.size();
  {
    std::string csv = "x_m,surface_initial_m,surface_m,vertical_displacement_m\n";
    for (std::size_t k = 0; k < nc; ++k)
      csv += fmt::format("{},{},{},{}\n", column_centre(k, 0), surface0_[k], now[k], -drop[k]);
    io::write_file_atomic(dir / "surface_profile.csv", csv);
  }
  // The crater: the connected columns around the deepest drop that dropped by more than a
  // grain radius.
  std::size_t deepest = nc;
  for (std::size_t k = 0; k < nc; ++k)
    if (std::isfinite(drop[k]) && (deepest == nc || drop[k] > drop[deepest])) deepest = k;
  std::vector<std::uint8_t> crater(nc, 0);
  Index crater_columns = 0;
  Real depth = 0;
  if (deepest < nc && drop[deepest] > grain_r_max_) {
    depth = drop[deepest];
    std::vector<std::size_t> stack{deepest};
    crater[deepest] = 1;
    while (!stack.empty()) {
      const std::size_t k = stack.back();
      stack.pop_back();
      ++crater_columns;
      for_each_neighbour(k, [&](std::size_t q) {
        if (!crater[q] && std::isfinite(drop[q]) && drop[q] > grain_r_max_) {
          crater[q] = 1;
          stack.push_back(q);
        }
      });
    }
  }
  const Real crater_radius = static_cast<Real>(crater_columns) * width_[0] / 2;
  // Settlement outside the crater and its neighbouring columns.
  Real settle = -std::numeric_limits<Real>::infinity(), settle_x = kNaN;
  for (std::size_t k = 0; k < nc; ++k) {
    if (!std::isfinite(drop[k]) || crater[k]) continue;
    bool next_to_crater = false;
    for_each_neighbour(k, [&](std::size_t q) { next_to_crater = next_to_crater || crater[q]; });
    if (next_to_crater) continue;
    if (drop[k] > settle) {
      settle = drop[k];
      settle_x = column_centre(k, 0);
    }
  }
  if (std::isfinite(settle)) {
    m.push_back({"surface_settlement_max_m", settle});
    m.push_back({"surface_settlement_max_x_m", settle_x});
  }
  m.push_back({"crater_depth_m", depth});
  m.push_back({"crater_radius_m", crater_radius});
  // The crater's columns reach a side of the domain that is not a plane of symmetry: its width
  // is the domain's, a lower bound.
  const bool at_side =
      nc > 0 && ((crater[0] && !mirror_side_[0]) || (crater[nc - 1] && !mirror_side_[1]));
  m.push_back({"crater_radius_lower_bound", at_side ? 1.0 : 0.0});
}

// 3D: the surface averaged in rings about the crater's axis, the crater read off that profile
// (probe_geometry.hpp) and the settlement of the rings outside it. A blast under a flat ground
// is axisymmetric about its axis: the rings keep what a single column's packing noise hides.
template <int D>
void Probes<D>::ring_crater_metrics(const std::vector<Real>& now, const std::filesystem::path& dir,
                                    std::vector<Diagnostic>& m) const {
  if constexpr (D == 3) {
    const std::size_t nc = now.size();
    std::vector<Real> r(nc);
    for (std::size_t k = 0; k < nc; ++k)
      r[k] = std::hypot(column_centre(k, 0) - cfg_.axis_m[0], column_centre(k, 1) - cfg_.axis_m[1]);
    // With vertical planes of symmetry through the axis (a half or quarter model), the modelled
    // columns of a ring are a half or quarter of the full model's, mirror images of the rest:
    // their mean is already the full ring's.
    const Real width = std::sqrt(width_[0] * width_[1]);
    const std::vector<Ring> rings = ring_profile(r, surface0_, now, width);
    std::string csv = "r_m,surface_initial_m,surface_m,dz_m\n";
    for (const Ring& g : rings)
      csv += fmt::format("{},{},{},{}\n", g.r_m, g.surface0_m, g.surface_m, -g.drop_m());
    io::write_file_atomic(dir / "surface_profile.csv", csv);
    const CraterSize crater = crater_of_profile(rings, grain_r_max_);
    // Settlement: the rings outside the crater and the ring next to it.
    Real settle = -std::numeric_limits<Real>::infinity(), settle_r = kNaN;
    for (const Ring& g : rings) {
      if (crater.depth_m > 0 && g.r_m <= crater.radius_m + width) continue;
      if (g.drop_m() > settle) {
        settle = g.drop_m();
        settle_r = g.r_m;
      }
    }
    if (std::isfinite(settle)) {
      m.push_back({"surface_settlement_max_m", settle});
      m.push_back({"surface_settlement_max_r_m", settle_r});
    }
    m.push_back({"crater_depth_m", crater.depth_m});
    m.push_back({"crater_radius_m", crater.radius_m});
    m.push_back({"crater_radius_lower_bound", crater.reaches_end ? 1.0 : 0.0});
    m.push_back({"crater_axis_x_m", cfg_.axis_m[0]});
    m.push_back({"crater_axis_y_m", cfg_.axis_m[1]});
  }
}

// The largest gap between the plate's live nodes and the grains below or above them, per
// column (delamination).
template <int D>
void Probes<D>::gap_metrics(const std::vector<std::unique_ptr<Part<D>>>& parts,
                            const std::vector<Column>& cols, const std::vector<Real>& now,
                            std::vector<Diagnostic>& m) const {
  const std::size_t nc = cols.size();
  const auto& plate = *parts[*cfg_.plate];
  const Geometry<D> g = plate.geometry();
  const auto eroded_views = plate.cell_fields();  // the views eroded points into
  const auto* eroded = fields::find_field(eroded_views, "eroded");
  const auto& xn = *g.points;
  std::vector<std::uint8_t> live(xn.size(), 0);
  std::int64_t begin = 0;
  for (std::size_t e = 0; e < g.offsets.size(); ++e) {
    if (!eroded_at(eroded, e))
      for (std::int64_t k = begin; k < g.offsets[e]; ++k)
        live[at(g.connectivity[at(k)])] = 1;
    begin = g.offsets[e];
  }
  const Real inf = std::numeric_limits<Real>::infinity();
  std::vector<Real> plate_lo(nc, inf), plate_hi(nc, -inf);
  for (std::size_t n = 0; n < xn.size(); ++n) {
    if (!live[n]) continue;
    Index col = 0;
    if (!column_of(xn[n], col)) continue;
    plate_lo[at(col)] = std::min(plate_lo[at(col)], xn[n][D - 1]);
    plate_hi[at(col)] = std::max(plate_hi[at(col)], xn[n][D - 1]);
  }
  const auto& soil = *parts[*cfg_.soil];
  const auto radius_views = soil.point_fields();  // the views radius points into
  const auto* radius = fields::find_field(radius_views, "radius");
  const auto& xs = *soil.geometry().points;
  Real gap_max = 0;
  for (std::size_t k = 0; k < nc; ++k) {
    if (!(plate_lo[k] <= plate_hi[k])) continue;
    Real below = -inf, above = inf;
    for (std::size_t r = 0; r < cols[k].grains.size(); ++r) {
      for (Index i : cols[k].grains[r]) {
        const Real z = xs[at(i)][D - 1], rad = radius->real_data[i];
        if (z < plate_lo[k]) below = std::max(below, z + rad);
        if (z > plate_hi[k]) above = std::min(above, z - rad);
      }
    }
    if (std::isfinite(below)) gap_max = std::max(gap_max, plate_lo[k] - below);
    if (std::isfinite(above) && std::isfinite(now[k]) && now[k] > plate_hi[k] + bin_)
      gap_max = std::max(gap_max, above - plate_hi[k]);
  }
  m.push_back({"delamination_gap_max_m", gap_max});
}

template <int D>
void Probes<D>::save(parts::StateWriter& w) const {
  w.tag("probes");
  w.value(phi_ref_);
  w.vector(surface0_);
  w.value(peak_at_time_);
  w.value(peak_time_s_);
  w.value(peak_max_);
  if (lining_) lining_->save(w);
}

template <int D>
void Probes<D>::load(parts::StateReader& r) {
  r.tag("probes");
  r.value(phi_ref_);
  r.vector(surface0_);
  r.value(peak_at_time_);
  r.value(peak_time_s_);
  r.value(peak_max_);
  if (lining_) lining_->load(r);
}

template class Probes<2>;
template class Probes<3>;

}  // namespace crater::solver
