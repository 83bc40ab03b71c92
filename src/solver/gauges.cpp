// [[gauges]] (gauges.hpp): resolving each gauge on the built parts, and gauges.csv's rows.
#include "solver/gauges.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "core/error.hpp"
#include "fields/field_set.hpp"
#include "parts/setup.hpp"

namespace crater::solver {

namespace {

constexpr Real kNaN = std::numeric_limits<Real>::quiet_NaN();
constexpr const char* kVectorSuffix[] = {"_x", "_y", "_z"};
constexpr const char* kTensorSuffix[] = {"_xx", "_yy", "_zz", "_xy", "_yz", "_xz"};

std::string field_list(const std::vector<fields::FieldView>& a,
                       const std::vector<fields::FieldView>& b) {
  std::string s;
  for (const auto* views : {&a, &b})
    for (const auto& v : *views)
      s += (s.empty() ? "" : ", ") + v.info->name;
  return s;
}

// The index of the entity nearest x among points.
template <int D>
std::int64_t nearest(const std::vector<Vec<D>>& points, const parts::Vec3& x) {
  std::int64_t best = -1;
  Real best_d2 = std::numeric_limits<Real>::infinity();
  for (std::size_t k = 0; k < points.size(); ++k) {
    Real d2 = 0;
    for (int d = 0; d < D; ++d)
      d2 += (points[k][d] - x[static_cast<std::size_t>(d)]) *
            (points[k][d] - x[static_cast<std::size_t>(d)]);
    if (d2 < best_d2) best_d2 = d2, best = static_cast<std::int64_t>(k);
  }
  return best;
}

// The centres of a mesh's cells (the mean of their nodes).
template <int D>
std::vector<Vec<D>> cell_centres(const parts::Geometry<D>& g) {
  std::vector<Vec<D>> c(g.offsets.size(), Vec<D>::Zero());
  std::int64_t from = 0;
  for (std::size_t e = 0; e < g.offsets.size(); ++e) {
    for (std::int64_t k = from; k < g.offsets[e]; ++k)
      c[e] += (*g.points)[static_cast<std::size_t>(g.connectivity[static_cast<std::size_t>(k)])];
    c[e] /= static_cast<Real>(std::max<std::int64_t>(g.offsets[e] - from, 1));
    from = g.offsets[e];
  }
  return c;
}

// The index of the particle with this id, -1 when it has left. Particles are reordered (sorted
// for memory locality), so a scan of the id field: the only pass a row makes over a part.
std::int64_t index_of_id(const fields::FieldView& ids, std::int64_t id) {
  const std::int64_t* b = ids.integer_data;
  const std::int64_t* e = b + ids.size;
  const std::int64_t* it = std::find(b, e, id);
  return it != e ? it - b : -1;
}

// The indices of all these ids at once (one scan of the id field), -1 for those that have left.
std::vector<std::int64_t> indices_of_ids(const fields::FieldView& ids,
                                         const std::vector<std::int64_t>& wanted) {
  std::vector<std::int64_t> sorted = wanted;
  std::sort(sorted.begin(), sorted.end());
  std::vector<std::int64_t> at_sorted(sorted.size(), -1);
  for (std::int64_t k = 0; k < ids.size; ++k) {
    const auto it = std::lower_bound(sorted.begin(), sorted.end(), ids.integer_data[k]);
    if (it != sorted.end() && *it == ids.integer_data[k]) at_sorted[it - sorted.begin()] = k;
  }
  std::vector<std::int64_t> out;
  for (std::int64_t id : wanted)
    out.push_back(at_sorted[std::lower_bound(sorted.begin(), sorted.end(), id) - sorted.begin()]);
  return out;
}

}  // namespace

template <int D>
Gauges<D>::Gauges(const io::Config& c, const PartList& parts) {
  for (std::size_t gi = 0; gi < c.gauges.size(); ++gi) {
    const io::GaugeConfig& g = c.gauges[gi];
    const std::string key = fmt::format("gauges[{}]", gi);
    const parts::Part<D>& p = *parts[g.part];
    const auto pviews = p.point_fields();
    const auto cviews = p.cell_fields();
    const fields::FieldView* ids = fields::find_field(pviews, "id");
    const parts::Geometry<D> geo = p.geometry();
    const bool particles = geo.connectivity.empty();
    for (std::size_t fi = 0; fi < g.fields.size(); ++fi) {
      const std::string& name = g.fields[fi];
      const std::string fkey = fmt::format("{}.fields[{}]", key, fi);
      Read r;
      r.part = g.part;
      r.field = name;
      const fields::FieldView* v = fields::find_field(pviews, name);
      if (!v) {
        v = fields::find_field(cviews, name);
        r.cell = v != nullptr;
      }
      if (!v)
        throw InputError(g.where, fkey,
                         fmt::format("no output field '{}' in part '{}' (its fields: {}){}", name,
                                     p.name(), field_list(pviews, cviews),
                                     particles && name == "stress"
                                         ? "; a DEM part's stress is computed at frames only"
                                         : ""));
      r.components = v->components;
      r.sum = g.sum;
      std::string kind = r.cell ? "element" : particles ? "particle" : "node";
      if (r.cell && g.face) {
        throw InputError(g.where, fkey,
                         fmt::format("'{}' is an element field; a face selects nodes (point "
                                     "fields such as reaction_force)",
                                     name));
      } else if (r.cell) {
        if (g.point_m) {
          r.entities.push_back(nearest<D>(cell_centres(geo), *g.point_m));
        } else if (g.element_ids.empty()) {
          throw InputError(
              g.where, key + ".element_ids",
              fmt::format("'{}' is an element field: give element_ids or point_m", name));
        } else {
          r.entities = g.element_ids;
        }
      } else {
        r.by_particle_id = particles && ids != nullptr;
        if (g.face) {
          r.entities = parts::points_on_face<D>(p.points(), *g.face);
        } else if (g.point_m) {
          const std::int64_t k = nearest<D>(p.points(), *g.point_m);
          r.entities.push_back(r.by_particle_id && k >= 0 ? ids->integer_data[k] : k);
        } else if (g.ids.empty()) {
          throw InputError(g.where, key + ".ids",
                           fmt::format("'{}' is a {} field: give ids or point_m", name, kind));
        } else {
          r.entities = g.ids;
        }
      }
      for (std::int64_t id : r.entities) {
        const bool found =
            id >= 0 && (r.by_particle_id ? index_of_id(*ids, id) >= 0 : id < v->size);
        if (!found)
          throw InputError(g.where, key + (r.cell ? ".element_ids" : ".ids"),
                           fmt::format("part '{}' has no {} {} (it has {} {}s)", p.name(), kind, id,
                                       v->size, kind));
        if (!r.sum) add_columns(fmt::format("{}.{}{}.{}", g.name, kind, id, name), r.components);
      }
      if (r.sum) add_columns(fmt::format("{}.sum.{}", g.name, name), r.components);
      reads_.push_back(std::move(r));
    }
  }
}

template <int D>
void Gauges<D>::add_columns(const std::string& stem, int components) {
  for (int k = 0; k < components; ++k)
    columns_.push_back(stem + (components == 1   ? ""
                               : components == 6 ? kTensorSuffix[k]
                                                 : kVectorSuffix[k]));
}

template <int D>
std::string Gauges<D>::header() const {
  std::string s = "step,time_s";
  for (const auto& col : columns_)
    s += "," + col;
  return s + "\n";
}

template <int D>
std::string Gauges<D>::row(Index step, Real t_s, const PartList& parts) const {
  std::string s = fmt::format("{},{:.17g}", step, t_s);
  // Each gauged part's views once per row (an FEM part evaluates its derived fields for them).
  std::vector<
      std::optional<std::pair<std::vector<fields::FieldView>, std::vector<fields::FieldView>>>>
      views(parts.size());
  for (const Read& r : reads_) {
    auto& pv = views[r.part];
    if (!pv) pv.emplace(parts[r.part]->point_fields(), parts[r.part]->cell_fields());
    const fields::FieldView* v = fields::find_field(r.cell ? pv->second : pv->first, r.field);
    const fields::FieldView* ids = fields::find_field(pv->first, "id");
    const std::vector<std::int64_t> at = r.by_particle_id && ids
                                             ? indices_of_ids(*ids, r.entities)
                                             : std::vector<std::int64_t>(r.entities.size(), -1);
    std::vector<Real> sum(static_cast<std::size_t>(r.components), 0);
    for (std::size_t j = 0; j < r.entities.size(); ++j) {
      const std::int64_t k = r.by_particle_id ? at[j] : r.entities[j];
      const bool ok = v != nullptr && k >= 0 && k < v->size;
      for (int c = 0; c < r.components; ++c) {
        const std::size_t i = static_cast<std::size_t>(k) * static_cast<std::size_t>(r.components) +
                              static_cast<std::size_t>(c);
        const Real x = !ok             ? kNaN
                       : v->is_integer ? static_cast<Real>(v->integer_data[i])
                                       : v->real_data[i];
        if (r.sum)
          sum[static_cast<std::size_t>(c)] += x;
        else
          s += fmt::format(",{:.17g}", x);
      }
    }
    if (r.sum)
      for (Real x : sum)
        s += fmt::format(",{:.17g}", x);
  }
  return s + "\n";
}

template class Gauges<2>;
template class Gauges<3>;

}  // namespace crater::solver
