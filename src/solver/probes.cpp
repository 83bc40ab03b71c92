// The paper's measurements; see probes.hpp.
#include "solver/probes.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
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

// A part's local entities as the probes count them: on ranks its own alone (a ghost is another
// rank's, Part::own_numbers), each with its number in the whole part; on one rank every entity,
// numbered by its index.
struct Owned {
  std::optional<parts::OwnNumbers> numbers;
  bool point(Index i) const { return !numbers || numbers->point[at(i)] >= 0; }
  bool cell(Index e) const { return !numbers || numbers->cell[at(e)] >= 0; }
  std::int64_t cell_number(Index e) const { return numbers ? numbers->cell[at(e)] : e; }
};

// f(xn, nodes, count) for each live element of a mesh part that this rank owns (every one on one
// rank): its nodes' positions now, its node list (VTK connectivity into them) and their count.
template <int D, class F>
void for_each_own_live_element(const parts::Part<D>& part, F&& f) {
  const Owned own{part.own_numbers()};
  const Geometry<D> g = part.geometry();
  const auto eroded_views = part.cell_fields();  // the views eroded points into
  const auto* eroded = fields::find_field(eroded_views, "eroded");
  std::int64_t begin = 0;
  for (std::size_t e = 0; e < g.offsets.size(); ++e) {
    if (own.cell(static_cast<Index>(e)) && !eroded_at(eroded, e))
      f(*g.points, &g.connectivity[at(begin)], g.offsets[e] - begin);
    begin = g.offsets[e];
  }
}

// One rank's share of a ground cell: its terms' exact levels and its grains there.
struct CellShare {
  std::int64_t cell = 0, grains = 0;
  parallel::ReproducibleSum::Partials levels{};
};

// The plate's live nodes in a column: the lowest and the highest.
struct ColumnSpan {
  std::int64_t column = 0;
  Real lo = 0, hi = 0;
};

// The grains next to the plate in a column: the top of the highest under it and the bottom of
// the lowest over it.
struct ColumnReach {
  std::int64_t column = 0;
  Real below = 0, above = 0;
};

// Records sorted by `key`, those with the same key merged by `merge(into, from)` (exact: a
// minimum, a maximum, a sum of exact levels), in place.
template <class T, class Key, class Merge>
void merge_by_key(std::vector<T>& v, Key&& key, Merge&& merge) {
  std::sort(v.begin(), v.end(), [&](const T& a, const T& b) { return key(a) < key(b); });
  std::size_t out = 0;
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (out > 0 && key(v[out - 1]) == key(v[k]))
      merge(v[out - 1], v[k]);
    else
      v[out++] = v[k];
  }
  v.resize(out);
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
bool Probes<D>::cell_of(const Vec<D>& x, std::int64_t& cell) const {
  Index col = 0;
  if (!column_of(x, col)) return false;
  const Real f = std::floor((x[D - 1] - lo_[D - 1]) / bin_);
  if (!(f >= 0 && f < static_cast<Real>(rows_))) return false;
  cell = static_cast<std::int64_t>(col) * rows_ + static_cast<Index>(f);
  return true;
}

template <int D>
template <class F>
void Probes<D>::for_each_ground_grain(const Part<D>& soil, F&& f) const {
  const Owned own{soil.own_numbers()};
  const auto pf = soil.point_fields();  // the views the fields point into
  const auto* radius = fields::find_field(pf, "radius");
  const auto* contacts = fields::find_field(pf, "contacts");
  const auto* velocity = fields::find_field(pf, "velocity");
  const auto& xs = *soil.geometry().points;
  for (Index i = 0; i < static_cast<Index>(xs.size()); ++i) {
    std::int64_t cell = 0;
    if (!own.point(i) || !cell_of(xs[at(i)], cell)) continue;
    if (contacts && velocity &&
        airborne(contacts->real_data[i], &velocity->real_data[D * i], radius->real_data[i]))
      continue;
    f(i, cell, xs[at(i)], radius->real_data[i]);
  }
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
  if (cfg_.plate) {
    const Geometry<D> g = parts[*cfg_.plate]->geometry();  // at t = 0: the reference
    plate_x0_ = *g.points;
    plate_connectivity_ = g.connectivity;
    plate_offsets_ = g.offsets;
  }
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
  // cells above and below (inside the bed). The parts are whole here, before any step or
  // resume, on every rank alike.
  const parallel::Comm whole;
  phi_ref_ = 1;
  {
    const auto cols = ground(parts, whole, /*with_plate=*/false);  // F: the grains' volume
    const Real cell = cell_volume_ground();
    std::vector<Real> inside;
    for (const auto& col : cols)
      for (std::size_t k = 1; k + 1 < col.grains.size(); ++k)
        if (col.grains[k] > 0 && col.grains[k - 1] > 0 && col.grains[k + 1] > 0)
          inside.push_back(col.filled[k] / cell);
    if (!inside.empty()) {
      std::nth_element(inside.begin(), inside.begin() + static_cast<long>(inside.size() / 2),
                       inside.end());
      phi_ref_ = std::clamp(inside[inside.size() / 2], Real(0.05), Real(1));
    }
  }
  const auto cols = ground(parts, whole);
  surface0_.resize(cols.size());
  for (std::size_t k = 0; k < cols.size(); ++k)
    surface0_[k] = surface_height(cols[k], k);
}

template <int D>
std::vector<typename Probes<D>::Column> Probes<D>::ground(
    const std::vector<std::unique_ptr<Part<D>>>& parts, const parallel::Comm& comm,
    bool with_plate) const {
  // Each rank's terms: its own grains', and its own live elements' where the plate was laid,
  // each in the cell of its centre (col * rows_ + row).
  struct Term {
    std::int64_t cell;
    Real volume;
    bool grain;
  };
  std::vector<Term> terms;
  for_each_ground_grain(*parts[*cfg_.soil], [&](Index, std::int64_t cell, const Vec<D>&, Real r) {
    terms.push_back({cell, dem::grain_volume<D>(r) / phi_ref_, true});
  });
  if (cfg_.plate && with_plate)
    for_each_own_live_element<D>(
        *parts[*cfg_.plate],
        [&](const std::vector<Vec<D>>& xn, const std::int64_t* nodes, std::int64_t n) {
          Vec<D> centre = Vec<D>::Zero();
          for (std::int64_t k = 0; k < n; ++k)
            centre += xn[at(nodes[k])];
          centre /= static_cast<Real>(n);
          std::int64_t cell = 0;
          // Only where the plate was laid (cells reaching into the soil's holes): a piece torn
          // off and thrown up is not the ground.
          if (cell_of(centre, cell) && hole_[at(cell / rows_)][at(cell % rows_)])
            terms.push_back({cell, element_volume<D>(xn, nodes), false});
        });
  // One sum per cell, made with the bounds of every rank's terms: a cell's levels are exact,
  // whichever rank adds which term and in whatever order (reproducible_sum.hpp).
  Real bound = 0;
  for (const Term& t : terms)
    if (std::isfinite(t.volume)) bound = std::max(bound, std::abs(t.volume));
  bound = comm.max(bound);
  const std::int64_t count = comm.sum(static_cast<std::int64_t>(terms.size()));
  std::sort(terms.begin(), terms.end(),
            [](const Term& a, const Term& b) { return a.cell < b.cell; });
  std::vector<CellShare> mine;
  for (std::size_t k = 0; k < terms.size();) {
    parallel::ReproducibleSum sum(bound, count);
    CellShare share{terms[k].cell, 0, {}};
    for (; k < terms.size() && terms[k].cell == share.cell; ++k) {
      sum.add(terms[k].volume);
      share.grains += terms[k].grain ? 1 : 0;
    }
    share.levels = sum.partials();
    mine.push_back(share);
  }
  std::vector<CellShare> all = parallel::gather(comm, std::span<const CellShare>(mine));
  if (!comm.root()) return {};
  merge_by_key(
      all, [](const CellShare& c) { return c.cell; },
      [](CellShare& into, const CellShare& from) {
        into.grains += from.grains;
        for (std::size_t q = 0; q < into.levels.size(); ++q)
          into.levels[q] += from.levels[q];
      });
  Index ncol = 1;
  for (int d = 0; d + 1 < D; ++d)
    ncol *= columns_[d];
  std::vector<Column> cols(at(ncol));
  for (auto& c : cols) {
    c.filled.assign(at(rows_), 0);
    c.grains.assign(at(rows_), 0);
  }
  for (const CellShare& c : all) {
    parallel::ReproducibleSum sum(bound, count);
    sum.set_partials(c.levels);
    cols[at(c.cell / rows_)].filled[at(c.cell % rows_)] = sum.value();
    cols[at(c.cell / rows_)].grains[at(c.cell % rows_)] = c.grains;
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
std::vector<Diagnostic> Probes<D>::finish(const std::vector<std::unique_ptr<Part<D>>>& parts,
                                          const std::filesystem::path& dir,
                                          const parallel::Comm* spread) const {
  const parallel::Comm single;
  const parallel::Comm& comm = spread ? *spread : single;
  std::vector<Diagnostic> m;
  if (cfg_.plate) plate_metrics(parts, comm, m);
  if (cfg_.soil) ground_metrics(parts, comm, dir, m);
  if (lining_) lining_->metrics(parts, dir, m, spread);
  return m;
}

// The plate's peak stresses, its eroded elements, and whether eroded elements sharing nodes
// connect its bottom face to its top face (perforation). Each rank sends the numbers of the
// eroded elements it owns to the root, which places them in the mesh at t = 0.
template <int D>
void Probes<D>::plate_metrics(const std::vector<std::unique_ptr<Part<D>>>& parts,
                              const parallel::Comm& comm, std::vector<Diagnostic>& m) const {
  const auto& plate = *parts[*cfg_.plate];
  const Real peak_now = plate_max_von_mises(parts, &comm);
  const Owned own{plate.own_numbers()};
  const auto cf = plate.cell_fields();
  const auto* eroded = fields::find_field(cf, "eroded");
  std::vector<std::int64_t> gone_here;
  for (Index e = 0; eroded && e < eroded->size; ++e)
    if (own.cell(e) && eroded_at(eroded, at(e))) gone_here.push_back(own.cell_number(e));
  const std::vector<std::int64_t> gone_numbers =
      parallel::gather(comm, std::span<const std::int64_t>(gone_here));
  if (!comm.root()) return;
  if (peak_time_s_ >= 0) {
    m.push_back({"plate_peak_von_mises_pa", peak_at_time_});
    m.push_back({"plate_peak_von_mises_time_s", peak_time_s_});
  }
  m.push_back({"plate_peak_von_mises_max_pa", std::max(peak_max_, peak_now)});
  const Index ne = static_cast<Index>(plate_offsets_.size());
  std::vector<std::uint8_t> gone(at(ne), 0);
  for (const std::int64_t e : gone_numbers)
    gone[at(e)] = 1;
  // Erosion and perforation: eroded elements sharing nodes, from bottom face to top face of
  // the undeformed plate.
  const auto& x0 = plate_x0_;
  const auto& conn = plate_connectivity_;
  auto first = [&](Index e) { return e == 0 ? std::int64_t{0} : plate_offsets_[at(e - 1)]; };
  Real zmin = std::numeric_limits<Real>::infinity(), zmax = -zmin;
  for (const Vec<D>& x : x0) {
    zmin = std::min(zmin, x[D - 1]);
    zmax = std::max(zmax, x[D - 1]);
  }
  const Real tol = 1e-6 * std::max(Real(1e-3), zmax - zmin);
  // Union-find over eroded elements through shared nodes.
  std::vector<Index> parent(at(ne));
  std::iota(parent.begin(), parent.end(), Index{0});
  auto find = [&](Index e) {
    while (parent[at(e)] != e)
      e = parent[at(e)] = parent[at(parent[at(e)])];
    return e;
  };
  std::vector<Index> node_owner(x0.size(), -1);
  for (Index e = 0; e < ne; ++e) {
    if (!gone[at(e)]) continue;
    for (std::int64_t k = first(e); k < plate_offsets_[at(e)]; ++k) {
      const auto node = at(conn[at(k)]);
      if (node_owner[node] < 0)
        node_owner[node] = e;
      else
        parent[at(find(e))] = find(node_owner[node]);
    }
  }
  std::vector<std::uint8_t> bottom(at(ne), 0), top(at(ne), 0);
  for (Index e = 0; e < ne; ++e) {
    if (!gone[at(e)]) continue;
    const Index root = find(e);
    for (std::int64_t k = first(e); k < plate_offsets_[at(e)]; ++k) {
      const Real z = x0[at(conn[at(k)])][D - 1];
      if (z <= zmin + tol) bottom[at(root)] = 1;
      if (z >= zmax - tol) top[at(root)] = 1;
    }
  }
  bool perforated = false;
  for (Index e = 0; e < ne; ++e)
    perforated = perforated || (bottom[at(e)] && top[at(e)]);
  m.push_back({"plate_eroded_elements", static_cast<Real>(gone_numbers.size())});
  m.push_back({"plate_perforated", perforated ? Real(1) : Real(0)});
  // The undeformed footprint that only eroded elements cover, the full model's (mirrored in
  // the vertical symmetry planes); in 2D a length, x 1 m of depth.
  const Real area = perforated_footprint<D>({x0, conn, plate_offsets_, gone}) * mirror_factor_;
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
                               const parallel::Comm& comm, const std::filesystem::path& dir,
                               std::vector<Diagnostic>& m) const {
  // Ground surface now and at t = 0 (the cells on the root).
  const auto cols = ground(parts, comm);
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
  if (comm.root()) {
    if constexpr (D == 2)
      column_crater_metrics(now, drop, dir, m);
    else
      ring_crater_metrics(now, dir, m);
  }
  if (cfg_.plate) gap_metrics(parts, comm, now, m);
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
// column (delamination). Each rank finds the columns' extremes over the nodes of its own live
// elements and over its own grains; the extremes over the ranks are exact. `now`: the surface
// per column, on the root.
template <int D>
void Probes<D>::gap_metrics(const std::vector<std::unique_ptr<Part<D>>>& parts,
                            const parallel::Comm& comm, const std::vector<Real>& now,
                            std::vector<Diagnostic>& m) const {
  const Real inf = std::numeric_limits<Real>::infinity();
  // The plate's live nodes per column, on every rank.
  std::vector<ColumnSpan> spans;
  for_each_own_live_element<D>(*parts[*cfg_.plate], [&](const std::vector<Vec<D>>& xn,
                                                        const std::int64_t* nodes, std::int64_t n) {
    for (std::int64_t k = 0; k < n; ++k) {
      const Vec<D>& x = xn[at(nodes[k])];
      Index col = 0;
      if (column_of(x, col)) spans.push_back({col, x[D - 1], x[D - 1]});
    }
  });
  auto column = [](const auto& r) { return r.column; };
  auto widen = [](ColumnSpan& into, const ColumnSpan& from) {
    into.lo = std::min(into.lo, from.lo);
    into.hi = std::max(into.hi, from.hi);
  };
  merge_by_key(spans, column, widen);
  if (comm.size() > 1) {
    spans = parallel::all_gather(comm, std::span<const ColumnSpan>(spans));
    merge_by_key(spans, column, widen);
  }
  // The grains next to the plate in its columns: those of the ground's cells (inside the
  // domain, not in free flight).
  std::vector<ColumnReach> reach(spans.size());
  for (std::size_t j = 0; j < spans.size(); ++j)
    reach[j] = {spans[j].column, -inf, inf};
  for_each_ground_grain(*parts[*cfg_.soil], [&](Index, std::int64_t cell, const Vec<D>& x, Real r) {
    const std::int64_t col = cell / rows_;
    const auto it =
        std::lower_bound(spans.begin(), spans.end(), col,
                         [](const ColumnSpan& s, std::int64_t c) { return s.column < c; });
    if (it == spans.end() || it->column != col) return;
    ColumnReach& reached = reach[static_cast<std::size_t>(it - spans.begin())];
    const Real z = x[D - 1];
    if (z < it->lo) reached.below = std::max(reached.below, z + r);
    if (z > it->hi) reached.above = std::min(reached.above, z - r);
  });
  std::vector<ColumnReach> all = parallel::gather(comm, std::span<const ColumnReach>(reach));
  if (!comm.root()) return;
  merge_by_key(all, column, [](ColumnReach& into, const ColumnReach& from) {
    into.below = std::max(into.below, from.below);
    into.above = std::min(into.above, from.above);
  });
  Real gap_max = 0;
  for (std::size_t j = 0; j < spans.size(); ++j) {
    const auto k = at(spans[j].column);
    const ColumnReach& r = all[j];
    if (std::isfinite(r.below)) gap_max = std::max(gap_max, spans[j].lo - r.below);
    if (std::isfinite(r.above) && std::isfinite(now[k]) && now[k] > spans[j].hi + bin_)
      gap_max = std::max(gap_max, r.above - spans[j].hi);
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
