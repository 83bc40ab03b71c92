// The scenario reader (reader.hpp): [[contacts]] and [probes].
#include <fmt/format.h>
#include <toml++/toml.h>
#include <algorithm>
#include <array>
#include <cmath>

#include "io/scenario/reader.hpp"

namespace crater::io::reader {

void Builder::read_contacts(Config& c, const SourceLocation& top) {
  const toml::node* cn = root_.get("contacts");
  if (!cn) return;
  const auto& arr = *cn->as_array();
  for (std::size_t i = 0; i < arr.size(); ++i) {
    const auto& t = *arr.get(i)->as_table();
    const SourceLocation w = where_of(t, top);
    const std::string key = fmt::format("contacts[{}]", i);
    ContactConfig k;
    k.where = w;
    k.penalty_scale = num(t, "penalty_scale");
    k.friction = num(t, "friction");
    k.damping_ratio = num(t, "damping_ratio");
    const auto& names = *t.get("parts")->as_array();
    const SourceLocation pw = loc(t, "parts", w);
    if (names.size() != 2) {
      error(pw, key + ".parts", fmt::format("expected two part names, got {}", names.size()));
      continue;
    }
    std::array<Method, 2> methods{};
    bool ok = true;
    for (std::size_t j = 0; j < 2; ++j) {
      const std::string name = names.get(j)->as_string()->get();
      const auto it = std::find_if(c.parts.begin(), c.parts.end(),
                                   [&](const PartConfig& p) { return p.name == name; });
      if (it == c.parts.end()) {
        std::string known;
        for (const auto& p : c.parts)
          known += (known.empty() ? "'" : ", '") + p.name + "'";
        error(pw, fmt::format("{}.parts[{}]", key, j),
              fmt::format("no part named '{}' (parts: {})", name, known));
        ok = false;
        continue;
      }
      k.parts[j] = static_cast<std::size_t>(it - c.parts.begin());
      methods[j] = it->method();
    }
    if (!ok) continue;
    // Particles against a solid's surface, or SPH against DEM particles.
    auto joins = [&](Method a, Method b) {
      return (methods[0] == a && methods[1] == b) || (methods[0] == b && methods[1] == a);
    };
    const bool supported = joins(Method::Dem, Method::Fem) || joins(Method::Dem, Method::Sph) ||
                           joins(Method::Fem, Method::Sph) || joins(Method::Fem, Method::Fem);
    if (!supported)
      error(pw, key + ".parts",
            fmt::format("contacts join sph or dem particles to an fem surface, sph to dem "
                        "particles, or two fem surfaces; '{}' and '{}' are {} and {}",
                        c.parts[k.parts[0]].name, c.parts[k.parts[1]].name, method_name(methods[0]),
                        method_name(methods[1])));
    read_surface_groups(c, t, w, key, k);
    for (const auto& other : c.contacts)
      if (std::minmax(other.parts[0], other.parts[1]) == std::minmax(k.parts[0], k.parts[1]))
        error(pw, key + ".parts",
              fmt::format("a second contact between '{}' and '{}' (first at line {})",
                          c.parts[k.parts[0]].name, c.parts[k.parts[1]].name, other.where.line));
    c.contacts.push_back(k);
  }
}

// [[contacts]] surface_groups: per part, a physical group of its mesh file (or "").
void Builder::read_surface_groups(const Config& c, const toml::table& t, const SourceLocation& w,
                                  const std::string& key, ContactConfig& k) {
  const toml::node* gn = t.get("surface_groups");
  if (!gn) return;
  const auto& groups = *gn->as_array();
  const SourceLocation gw = loc(t, "surface_groups", w);
  if (groups.size() != 2) {
    error(gw, key + ".surface_groups",
          fmt::format("expected two names, one per part in the order of parts (\"\": the whole "
                      "surface), got {}",
                      groups.size()));
    return;
  }
  for (std::size_t j = 0; j < 2; ++j) {
    const std::string g = groups.get(j)->as_string()->get();
    if (g.empty()) continue;
    const PartConfig& p = c.parts[k.parts[j]];
    const std::string gk = fmt::format("{}.surface_groups[{}]", key, j);
    if (!p.is(Method::Fem) || p.fem().mesh_file.empty()) {
      error(gw, gk,
            fmt::format("part '{}' {}: a surface group is a physical group of an fem part's "
                        "mesh_file; give \"\" for its whole surface",
                        p.name, p.is(Method::Fem) ? "has no mesh_file" : "is not an fem part"));
      continue;
    }
    const auto& mesh = p.fem().elements;
    if (mesh && !mesh->groups.count(g)) {
      std::string known;
      for (const auto& [name, set] : mesh->groups)
        known += (known.empty() ? "'" : ", '") + name + "'";
      error(gw, gk,
            fmt::format("no physical group '{}' with nodes of part '{}' in {} (groups: {})", g,
                        p.name, p.fem().mesh_file, known.empty() ? "none" : known));
      continue;
    }
    k.surface_groups[j] = g;
  }
}

// [probes] lining_axis_point_m and lining_axis_direction: the tunnel's axis.
void Builder::read_lining_axis(Config& c, const toml::table& t, const SourceLocation& w) {
  const int dim = c.dimension;
  if (!c.probes.lining) {
    for (const char* key : {"lining_axis_point_m", "lining_axis_direction"})
      if (t.get(key))
        error(loc(t, key, w), std::string("probes.") + key, "only used with probes.lining");
    return;
  }
  if (t.get("lining_axis_point_m")) {
    const std::vector<Real> p = reals(t, "lining_axis_point_m");
    if (static_cast<int>(p.size()) != dim) {
      error(loc(t, "lining_axis_point_m", w), "probes.lining_axis_point_m",
            fmt::format("expected {} numbers (a point), got {}", dim, p.size()));
      return;
    }
    for (std::size_t d = 0; d < p.size(); ++d)
      c.probes.lining_axis_point_m[d] = p[d];
  } else {
    error(loc(t, "lining", w), "probes.lining_axis_point_m",
          "expected the tunnel's axis: a point on it, e.g. lining_axis_point_m = [0.0, 0.0, 0.0]"
          " (the charge's centre)");
  }
  if (!t.get("lining_axis_direction")) return;
  const SourceLocation dw = loc(t, "lining_axis_direction", w);
  if (dim != 3) {
    error(dw, "probes.lining_axis_direction",
          "3D only: in 2D the axis is perpendicular to the plane");
    return;
  }
  const std::vector<Real> a = reals(t, "lining_axis_direction");
  if (a.size() != 3 || !(std::abs(a[2]) < 1e-12) || !(std::hypot(a[0], a[1]) > 0)) {
    error(dw, "probes.lining_axis_direction",
          "expected a horizontal direction [x, y, 0] (z is vertical), not zero");
    return;
  }
  c.probes.lining_axis_direction = {a[0], a[1], a[2]};
}

void Builder::read_probes(Config& c, const SourceLocation& top) {
  const toml::node* pn = root_.get("probes");
  if (!pn) return;
  const auto& t = *pn->as_table();
  const SourceLocation w = where_of(t, top);
  c.probes.stress_time_s = num(t, "stress_time_s");
  c.probes.surface_bin_m = opt_num(t, "surface_bin_m");
  auto part = [&](const char* key, Method method) -> std::optional<std::size_t> {
    const toml::node* n = t.get(key);
    if (!n) return std::nullopt;
    const std::string name = n->as_string()->get();
    const auto it = std::find_if(c.parts.begin(), c.parts.end(),
                                 [&](const PartConfig& p) { return p.name == name; });
    if (it == c.parts.end() || !it->is(method)) {
      std::string known;
      for (const auto& p : c.parts)
        if (p.is(method)) known += (known.empty() ? "'" : ", '") + p.name + "'";
      error(loc(t, key, w), std::string("probes.") + key,
            fmt::format("expected the name of a {} part ({}), got '{}'", method_name(method),
                        known.empty() ? std::string("the scenario has none") : known, name));
      return std::nullopt;
    }
    return static_cast<std::size_t>(it - c.parts.begin());
  };
  c.probes.plate = part("plate", Method::Fem);
  c.probes.soil = part("soil", Method::Dem);
  c.probes.lining = part("lining", Method::Fem);
  c.probes.lining_soil = part("lining_soil", Method::Fem);
  if (c.probes.lining_soil && !c.probes.lining)
    error(loc(t, "lining_soil", w), "probes.lining_soil",
          "only used with probes.lining (the crown line starts at the lining's crown)");
  if (c.probes.lining_soil && c.probes.lining && *c.probes.lining_soil == *c.probes.lining)
    error(loc(t, "lining_soil", w), "probes.lining_soil",
          "expected the part around the lining, not the lining itself");
  read_lining_axis(c, t, w);
  read_probe_axis(c, t, w);
  if (c.probes.plate && c.probes.stress_time_s > c.end_time_s)
    c_warnings_.push_back(
        fmt::format("probes.stress_time_s = {} s is after scenario.end_time_s = {} s: "
                    "plate_peak_von_mises_pa will not be measured",
                    c.probes.stress_time_s, c.end_time_s));
}

// [probes] axis_m: the crater's axis in 3D, given or resolved here so that the run and `check`
// use one value. The detonation point is where a buried charge's crater centres; without one,
// the full model's centre, which lies on the symmetry planes of a half or quarter model.
void Builder::read_probe_axis(Config& c, const toml::table& t, const SourceLocation& w) {
  const std::vector<Real> given = reals(t, "axis_m");
  if (t.get("axis_m")) {
    const SourceLocation aw = loc(t, "axis_m", w);
    if (c.dimension != 3) {
      error(aw, "probes.axis_m",
            "the crater's axis is for 3D scenarios (scenario.dimension = 3); a 2D surface "
            "profile is along x, per column");
      return;
    }
    if (given.size() != 2) {
      error(aw, "probes.axis_m",
            fmt::format("expected [x, y], the horizontal position of the crater's axis (2 "
                        "numbers), got {} entries",
                        given.size()));
      return;
    }
    bool outside = false;
    for (std::size_t d = 0; d < 2; ++d)
      outside = outside || given[d] < c.domain.min_m[d] || given[d] > c.domain.max_m[d];
    if (outside)
      c_warnings_.push_back(
          fmt::format("probes.axis_m = [{}, {}] is outside the domain's horizontal extent: "
                      "the surface profile is averaged about an axis outside the model",
                      given[0], given[1]));
    c.probes.axis_m = {given[0], given[1]};
    return;
  }
  if (c.dimension != 3 || !c.domain.bounded) return;  // unbounded: FEM only, no soil to probe
  for (const auto& p : c.parts)
    if (p.is(Method::Sph) && !p.detonations.empty()) {
      c.probes.axis_m = {p.detonations.front().point_m[0], p.detonations.front().point_m[1]};
      return;
    }
  for (std::size_t axis = 0; axis < 2; ++axis) {
    const auto lo = static_cast<parts::Face>(2 * axis);
    const auto hi = static_cast<parts::Face>(2 * axis + 1);
    if (parts::is_symmetry_plane(c.domain, lo))
      c.probes.axis_m[axis] = c.domain.min_m[axis];
    else if (parts::is_symmetry_plane(c.domain, hi))
      c.probes.axis_m[axis] = c.domain.max_m[axis];
    else
      c.probes.axis_m[axis] = Real(0.5) * (c.domain.min_m[axis] + c.domain.max_m[axis]);
  }
}

}  // namespace crater::io::reader
