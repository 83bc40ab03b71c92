// [[gauges]] (gauges.hpp): resolving each gauge on the built parts, and gauges.csv's rows.
#include "solver/gauges.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "core/error.hpp"
#include "fields/field_set.hpp"
#include "parallel/comm.hpp"
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

// The components of entity k of view v, as numbers, into out.
void value_at(const fields::FieldView& v, std::int64_t k, std::size_t components, Real* out) {
  for (std::size_t c = 0; c < components; ++c) {
    const std::size_t i = static_cast<std::size_t>(k) * components + c;
    out[c] = v.is_integer ? static_cast<Real>(v.integer_data[i]) : v.real_data[i];
  }
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

// Read r's values at its entities, entity after entity, each with its components: NaN for an
// entity the views do not hold (a particle that has left) or a field they lack.
template <int D>
std::vector<Real> Gauges<D>::values_of(const Read& r, const fields::FieldView* v,
                                       const fields::FieldView* ids) const {
  const auto n = static_cast<std::size_t>(r.components);
  std::vector<Real> out(r.entities.size() * n, kNaN);
  const std::vector<std::int64_t> at = r.by_particle_id && ids
                                           ? indices_of_ids(*ids, r.entities)
                                           : std::vector<std::int64_t>(r.entities.size(), -1);
  for (std::size_t j = 0; j < r.entities.size(); ++j) {
    const std::int64_t k = r.by_particle_id ? at[j] : r.entities[j];
    if (v != nullptr && k >= 0 && k < v->size) value_at(*v, k, n, &out[j * n]);
  }
  return out;
}

template <int D>
std::string Gauges<D>::row(Index step, Real t_s, const PartList& parts,
                           const parallel::Comm* comm) const {
  if (comm && comm->size() > 1) return row_on_ranks(step, t_s, parts, *comm);
  // Each gauged part's views once per row (an FEM part evaluates its derived fields for them).
  std::vector<
      std::optional<std::pair<std::vector<fields::FieldView>, std::vector<fields::FieldView>>>>
      views(parts.size());
  std::vector<std::vector<Real>> values;
  for (const Read& r : reads_) {
    auto& pv = views[r.part];
    if (!pv) pv.emplace(parts[r.part]->point_fields(), parts[r.part]->cell_fields());
    values.push_back(values_of(r, fields::find_field(r.cell ? pv->second : pv->first, r.field),
                               fields::find_field(pv->first, "id")));
  }
  return formatted(step, t_s, values);
}

// On ranks: each rank reads the gauged entities it owns (Part::own_numbers: a particle by its
// id, a node or element by its number) and sends them to the root as (read, entity slot,
// values) records, one gather a row; the root writes the row from them as one rank would
// (an entity no rank sent: NaN, a particle that has left). No part is gathered whole.
template <int D>
std::string Gauges<D>::row_on_ranks(Index step, Real t_s, const PartList& parts,
                                    const parallel::Comm& comm) const {
  struct Found {
    std::int64_t read, slot;
    std::array<Real, 6> x;
  };
  struct Seen {
    std::vector<fields::FieldView> point, cell;
    parts::OwnNumbers numbers;
  };
  std::vector<std::optional<Seen>> seen(parts.size());
  std::vector<Found> mine;
  for (std::size_t q = 0; q < reads_.size(); ++q) {
    const Read& r = reads_[q];
    auto& sv = seen[r.part];
    if (!sv) {
      auto numbers = parts[r.part]->own_numbers();
      if (!numbers)
        throw std::logic_error("gauges: part '" + parts[r.part]->name() + "' is not spread");
      sv.emplace(
          Seen{parts[r.part]->point_fields(), parts[r.part]->cell_fields(), std::move(*numbers)});
    }
    const fields::FieldView* v = fields::find_field(r.cell ? sv->cell : sv->point, r.field);
    if (!v) continue;
    // The gauged entities' slots by their numbers (a number may be gauged twice).
    std::vector<std::pair<std::int64_t, std::int64_t>> slot_of;
    for (std::size_t j = 0; j < r.entities.size(); ++j)
      slot_of.emplace_back(r.entities[j], static_cast<std::int64_t>(j));
    std::sort(slot_of.begin(), slot_of.end());
    const std::vector<std::int64_t>& number = r.cell ? sv->numbers.cell : sv->numbers.point;
    const auto n = static_cast<std::size_t>(r.components);
    if (n > std::tuple_size_v<decltype(Found::x)>)
      throw std::logic_error("gauges: field '" + r.field + "' has more components than a record");
    const std::int64_t local = std::min<std::int64_t>(v->size, std::ssize(number));
    for (std::int64_t i = 0; i < local; ++i) {
      const std::int64_t id = number[static_cast<std::size_t>(i)];
      if (id < 0) continue;
      auto it =
          std::lower_bound(slot_of.begin(), slot_of.end(), std::make_pair(id, std::int64_t{0}));
      for (; it != slot_of.end() && it->first == id; ++it) {
        Found& f = mine.emplace_back(Found{static_cast<std::int64_t>(q), it->second, {}});
        value_at(*v, i, n, f.x.data());
      }
    }
  }
  const std::vector<Found> all = parallel::gather(comm, std::span<const Found>(mine));
  if (!comm.root()) return {};
  std::vector<std::vector<Real>> values;
  for (const Read& r : reads_)
    values.emplace_back(r.entities.size() * static_cast<std::size_t>(r.components), kNaN);
  for (const Found& f : all) {
    const auto n = static_cast<std::size_t>(reads_[static_cast<std::size_t>(f.read)].components);
    std::copy_n(f.x.begin(), n,
                values[static_cast<std::size_t>(f.read)].begin() +
                    static_cast<std::ptrdiff_t>(static_cast<std::size_t>(f.slot) * n));
  }
  return formatted(step, t_s, values);
}

// The row from every read's values (entity after entity, each with its components): one column
// per value, or, for a sum, per component, summed in entity order.
template <int D>
std::string Gauges<D>::formatted(Index step, Real t_s,
                                 const std::vector<std::vector<Real>>& values) const {
  std::string s = fmt::format("{},{:.17g}", step, t_s);
  for (std::size_t q = 0; q < reads_.size(); ++q) {
    const Read& r = reads_[q];
    const auto n = static_cast<std::size_t>(r.components);
    std::vector<Real> sum(n, 0);
    for (std::size_t j = 0; j < r.entities.size(); ++j)
      for (std::size_t c = 0; c < n; ++c) {
        const Real x = values[q][j * n + c];
        if (r.sum)
          sum[c] += x;
        else
          s += fmt::format(",{:.17g}", x);
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
