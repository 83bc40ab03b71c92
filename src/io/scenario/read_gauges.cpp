// The scenario reader (reader.hpp): [[gauges]], history output at chosen entities.
#include <fmt/format.h>
#include <toml++/toml.h>
#include <algorithm>
#include <cmath>

#include "io/scenario/reader.hpp"

namespace crater::io::reader {

namespace {

// A gauge's name starts its columns: the characters of a part name.
bool good_name(const std::string& n) {
  return !n.empty() && n.size() <= 64 && std::all_of(n.begin(), n.end(), [](unsigned char ch) {
    return std::isalnum(ch) || ch == '_' || ch == '-' || ch == '.';
  });
}

}  // namespace

void Builder::read_gauge_ids(const toml::table& t, const SourceLocation& w, const std::string& key,
                             const char* k, std::vector<std::int64_t>& out) {
  const toml::node* n = t.get(k);
  if (!n) return;
  const auto& arr = *n->as_array();
  for (std::size_t j = 0; j < arr.size(); ++j) {
    const double v = arr.get(j)->value<double>().value_or(-1.0);
    if (!(v >= 0) || v != std::floor(v) || v > 9e15) {
      error(where_of(*arr.get(j), loc(t, k, w)), fmt::format("{}.{}[{}]", key, k, j),
            fmt::format("expected a whole number >= 0 (an entity id), got {}", v));
      continue;
    }
    out.push_back(static_cast<std::int64_t>(v));
  }
  if (out.empty()) error(loc(t, k, w), key + "." + k, "expected at least one id");
}

void Builder::read_gauges(Config& c, const SourceLocation& top) {
  const toml::node* gn = root_.get("gauges");
  if (!gn) return;
  const auto& arr = *gn->as_array();
  for (std::size_t i = 0; i < arr.size(); ++i) {
    const auto& t = *arr.get(i)->as_table();
    const SourceLocation w = where_of(t, top);
    const std::string key = fmt::format("gauges[{}]", i);
    GaugeConfig g;
    g.where = w;
    g.name = str(t, "name");
    if (!good_name(g.name))
      error(loc(t, "name", w), key + ".name",
            "expected 1-64 characters from A-Z a-z 0-9 _ - . (the name starts gauges.csv's "
            "columns)");
    for (const auto& other : c.gauges)
      if (other.name == g.name)
        error(
            loc(t, "name", w), key + ".name",
            fmt::format("duplicate gauge name '{}' (first at line {})", g.name, other.where.line));
    const std::string part = str(t, "part");
    const auto it = std::find_if(c.parts.begin(), c.parts.end(),
                                 [&](const PartConfig& p) { return p.name == part; });
    if (it == c.parts.end()) {
      std::string known;
      for (const auto& p : c.parts)
        known += (known.empty() ? "'" : ", '") + p.name + "'";
      error(loc(t, "part", w), key + ".part", fmt::format("no part '{}' (parts: {})", part, known));
      continue;
    }
    g.part = static_cast<std::size_t>(it - c.parts.begin());
    for (const auto& f : *t.get("fields")->as_array())
      g.fields.push_back(f.as_string()->get());
    if (g.fields.empty()) error(loc(t, "fields", w), key + ".fields", "expected a field name");
    if (t.get("point_m")) g.point_m = vec3(t, "point_m");
    read_gauge_ids(t, w, key, "ids", g.ids);
    read_gauge_ids(t, w, key, "element_ids", g.element_ids);
    const bool by_ids = t.get("ids") || t.get("element_ids");
    if (g.point_m && by_ids)
      error(loc(t, "point_m", w), key + ".point_m",
            "give either point_m or ids / element_ids, not both");
    if (t.get("face")) {
      const std::string face = str(t, "face");
      const int fi = face_index(face);
      if (!it->is(Method::Fem))
        error(loc(t, "face", w), key + ".face",
              fmt::format("a face selects nodes of an FEM part; '{}' is {}", part,
                          it->is(Method::Sph) ? "sph" : "dem"));
      else if (fi / 2 >= c.dimension)
        error(loc(t, "face", w), key + ".face",
              fmt::format("\"{}\" is a face of the z axis; the scenario is 2D", face));
      else if (g.point_m || by_ids)
        error(loc(t, "face", w), key + ".face",
              "give one of point_m, ids / element_ids and face, not several");
      else
        g.face = static_cast<parts::Face>(fi);
    } else if (!g.point_m && !by_ids) {
      error(w, key + ".point_m",
            "missing: a gauge needs point_m, ids (nodes, particles) / element_ids, or face (FEM)");
    }
    const bool sum = t.get("sum")->as_boolean()->get();
    g.sum = sum || g.face.has_value();
    if (sum && g.point_m)
      error(loc(t, "sum", w), key + ".sum",
            "a sum needs ids, element_ids or face; point_m selects one entity");
    if (t.get("element_ids") && !it->is(Method::Fem))
      error(loc(t, "element_ids", w), key + ".element_ids",
            fmt::format("only an FEM part has elements; '{}' is {}", part,
                        it->is(Method::Sph) ? "sph" : "dem"));
    c.gauges.push_back(std::move(g));
  }
}

}  // namespace crater::io::reader
