// The scenario reader (reader.hpp), [[parts]]: the keys every part has, its region and zones,
// the material it takes, carving, and the bodies' overlaps (with the region geometry).
#include <fmt/format.h>
#include <toml++/toml.h>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

#include "io/scenario/material_laws.hpp"
#include "io/scenario/reader.hpp"
#include "mesh/solid_mesh.hpp"

namespace crater::io::reader {

Aabb bounds(const RegionConfig& r, int dim) {
  Aabb b;
  for (int d = 0; d < dim; ++d) {
    if (r.type == RegionType::Box) {
      b.lo[d] = r.min_m[d];
      b.hi[d] = r.max_m[d];
    } else {
      b.lo[d] = r.center_m[d] - r.radius_m;
      b.hi[d] = r.center_m[d] + r.radius_m;
    }
  }
  return b;
}

Real volume(const RegionConfig& r, int dim) {
  if (r.type == RegionType::Box) {
    Real v = 1;
    for (int d = 0; d < dim; ++d)
      v *= r.max_m[d] - r.min_m[d];
    return v;
  }
  return dim == 2 ? M_PI * r.radius_m * r.radius_m
                  : 4.0 / 3.0 * M_PI * r.radius_m * r.radius_m * r.radius_m;
}

namespace {

// Distance from p to a box (0 inside).
Real distance_to_box(const Vec3& p, const Aabb& b, int dim) {
  Real s = 0;
  for (int d = 0; d < dim; ++d) {
    const Real e = std::max({b.lo[d] - p[d], 0.0, p[d] - b.hi[d]});
    s += e * e;
  }
  return std::sqrt(s);
}

// The validated `method` as the settings its reader fills: the alternative held is the method.
MethodConfig method_settings(const std::string& method) {
  if (method == "sph") return SphConfig{};
  if (method == "dem") return DemPartConfig{};
  return FemConfig{};  // the schema accepts only the three
}

}  // namespace

Real distance_to_region(const Vec3& p, const RegionConfig& r, int dim) {
  if (r.type == RegionType::Box) return distance_to_box(p, bounds(r, dim), dim);
  Real s = 0;
  for (int d = 0; d < dim; ++d)
    s += (p[d] - r.center_m[d]) * (p[d] - r.center_m[d]);
  return std::max(0.0, std::sqrt(s) - r.radius_m);
}

bool overlap(const RegionConfig& a, const RegionConfig& b, int dim) {
  const bool a_box = a.type == RegionType::Box, b_box = b.type == RegionType::Box;
  if (a_box && b_box) {
    const Aabb p = bounds(a, dim), q = bounds(b, dim);
    for (int d = 0; d < dim; ++d)
      if (p.hi[d] <= q.lo[d] || q.hi[d] <= p.lo[d]) return false;
    return true;
  }
  if (!a_box && !b_box) {
    Real s = 0;
    for (int d = 0; d < dim; ++d)
      s += (a.center_m[d] - b.center_m[d]) * (a.center_m[d] - b.center_m[d]);
    return std::sqrt(s) < a.radius_m + b.radius_m;
  }
  const RegionConfig& ball = a_box ? b : a;
  const RegionConfig& box = a_box ? a : b;
  return distance_to_box(ball.center_m, bounds(box, dim), dim) < ball.radius_m;
}

std::string vec_text(const Vec3& v, int dim) {
  return dim == 2 ? fmt::format("({}, {})", v[0], v[1])
                  : fmt::format("({}, {}, {})", v[0], v[1], v[2]);
}

std::string region_text(const RegionConfig& r, int dim) {
  if (r.type == RegionType::Box)
    return fmt::format("box {} .. {}", vec_text(r.min_m, dim), vec_text(r.max_m, dim));
  return fmt::format("{} of radius {} m about {}", r.type == RegionType::Disk ? "disk" : "sphere",
                     r.radius_m, vec_text(r.center_m, dim));
}

void Builder::read_parts(Config& c, const SourceLocation& top) {
  const auto& arr = *root_.get("parts")->as_array();
  for (std::size_t i = 0; i < arr.size(); ++i) {
    const auto& t = *arr.get(i)->as_table();
    c.parts.push_back(read_part(c, t, where_of(t, top), fmt::format("parts[{}]", i)));
  }
  read_carving(c, arr, top);
  check_overlaps(c);
}

// One part: the keys every part has, then its method's.
PartConfig Builder::read_part(const Config& c, const toml::table& t, const SourceLocation& w,
                              const std::string& key) {
  const int dim = c.dimension;
  PartConfig p;
  p.where = w;
  p.name = str(t, "name");
  p.settings = method_settings(str(t, "method"));
  // An FEM part read from a mesh file takes its geometry from the mesh; every other part
  // is a region filled at a spacing.
  const toml::node* fem_node = t.get("fem");
  const bool from_mesh = p.is(Method::Fem) && fem_node && fem_node->is_table() &&
                         fem_node->as_table()->get("mesh_file");
  // DEM grains placed by hand ([[parts.particles]]) need no lattice either.
  const bool by_hand = p.is(Method::Dem) && t.get("particles") != nullptr;
  if (from_mesh) {
    for (const char* k : {"spacing_m", "region"})
      if (t.get(k))
        error(loc(t, k, w), key + "." + k,
              "not used with fem.mesh_file (the mesh gives the geometry); remove it");
  } else if (by_hand) {
    for (const char* k : {"spacing_m", "region"})
      if (t.get(k))
        c_warnings_.push_back(
            fmt::format("part '{}': {} is not used, the part's grains are the "
                        "ones [[parts.particles]] places (line {}; remove it)",
                        p.name, k, loc(t, k, w).line));
  } else {
    for (const char* k : {"spacing_m", "region"})
      if (!t.get(k))
        error(w, key + "." + k,
              std::string("missing required key (") +
                  (k == std::string("region") ? "a table [parts.region]" : "a number, in m") + ")" +
                  (p.is(Method::Fem) ? ", or give fem.mesh_file" : ""));
  }
  p.spacing_m = opt_num(t, "spacing_m").value_or(0);
  for (const auto& other : c.parts)
    if (other.name == p.name)
      error(loc(t, "name", w), key + ".name",
            fmt::format("duplicate part name '{}' (first at line {})", p.name, other.where.line));
  const bool name_ok = !p.name.empty() && p.name.size() <= 64 && p.name.front() != '.' &&
                       std::all_of(p.name.begin(), p.name.end(), [](unsigned char ch) {
                         return std::isalnum(ch) || ch == '_' || ch == '-' || ch == '.';
                       });
  if (!name_ok)
    error(loc(t, "name", w), key + ".name",
          "expected 1-64 characters from A-Z a-z 0-9 _ - . (no spaces, control characters "
          "or path separators; not starting with '.'): the name names output files");

  const std::string mat = str(t, "material");
  auto it = std::find_if(c.materials.begin(), c.materials.end(),
                         [&](const MaterialConfig& m) { return m.name == mat; });
  if (it == c.materials.end()) {
    std::string known;
    for (const auto& m : c.materials)
      known += (known.empty() ? "" : ", ") + m.name;
    error(loc(t, "material", w), key + ".material",
          fmt::format("unknown material '{}' (defined: {})", mat, known));
  } else {
    p.material = static_cast<std::size_t>(it - c.materials.begin());
  }

  const toml::table* region_table = t.get("region") ? t.get("region")->as_table() : nullptr;
  if (region_table)
    p.region = read_region(*region_table, where_of(*region_table, w), key + ".region", dim);
  if (region_table && p.is(Method::Fem) && p.region.type != RegionType::Box)
    error(loc(*region_table, "type", w), key + ".region.type",
          "an FEM part's structured mesh fills a box; for other shapes give fem.mesh_file");

  const auto& it_init = table(t, "initial");
  p.initial.density_kg_m3 = opt_num(it_init, "density_kg_m3");
  p.initial.pressure_pa = opt_num(it_init, "pressure_pa");
  p.initial.velocity_m_s = vec3(it_init, "velocity_m_s");
  if (const toml::node* zn = t.get("zones")) read_zones(*zn->as_array(), w, key, dim, p);
  if (region_table) check_region(c, t, *region_table, w, key, p);
  if (p.material < c.materials.size()) check_method_material(c, t, w, key, p);
  if (!c.domain.bounded && !p.is(Method::Fem)) {
    error(loc(t, "method", w), key + ".method",
          "an SPH or DEM part needs [domain] min_m and max_m (the box its particles stay in); "
          "only an FEM-only scenario may leave them out");
    return p;
  }
  if (p.is(Method::Sph)) read_sph(c, t, w, key, p);
  if (p.is(Method::Dem)) read_dem(c, t, w, key, p);
  if (p.is(Method::Fem)) read_fem(c, t, w, key, p);
  return p;
}

void Builder::zones_velocity_only(const toml::table& t, const SourceLocation& w,
                                  const std::string& key, const char* why) {
  const toml::node* zn = t.get("zones");
  for (std::size_t j = 0; zn && j < zn->as_array()->size(); ++j) {
    const auto& zt = *zn->as_array()->get(j)->as_table();
    for (const char* k : {"spacing_m", "density_kg_m3", "pressure_pa"})
      if (zt.get(k)) error(loc(zt, k, w), fmt::format("{}.zones[{}].{}", key, j, k), why);
  }
}

// [[parts.zones]]: sub-regions with their own initial state (and lattice).
void Builder::read_zones(const toml::array& za, const SourceLocation& w, const std::string& key,
                         int dim, PartConfig& p) {
  for (std::size_t j = 0; j < za.size(); ++j) {
    const auto& zt = *za.get(j)->as_table();
    const SourceLocation zw = where_of(zt, w);
    ZoneConfig z;
    const auto& zr = table(zt, "region");
    z.region = read_region(zr, where_of(zr, zw), fmt::format("{}.zones[{}].region", key, j), dim);
    z.spacing_m = opt_num(zt, "spacing_m");
    if (z.spacing_m) check_zone_spacing(zt, zw, fmt::format("{}.zones[{}]", key, j), z, dim);
    z.density_kg_m3 = opt_num(zt, "density_kg_m3");
    z.pressure_pa = opt_num(zt, "pressure_pa");
    if (zt.get("velocity_m_s")) z.velocity_m_s = vec3(zt, "velocity_m_s");
    p.zones.push_back(z);
  }
}

// The material must suit the method.
void Builder::check_method_material(const Config& c, const toml::table& t, const SourceLocation& w,
                                    const std::string& key, const PartConfig& p) {
  const std::string& model = c.materials[p.material].model;
  if (p.method() != material_law(model).method)
    error(loc(t, "material", w), key + ".material",
          fmt::format("method \"{}\" needs {}; '{}' is \"{}\"", method_name(p.method()),
                      materials_of_method(p.method()), c.materials[p.material].name, model));
}

// Carving: a part may leave the regions of named other parts empty.
void Builder::read_carving(Config& c, const toml::array& arr, const SourceLocation& top) {
  for (std::size_t i = 0; i < arr.size(); ++i) {
    const auto& t = *arr.get(i)->as_table();
    const toml::node* cn = t.get("carve");
    if (!cn || i >= c.parts.size()) continue;
    const SourceLocation cw = loc(t, "carve", where_of(t, top));
    PartConfig& p = c.parts[i];
    if (p.is(Method::Fem))
      error(cw, fmt::format("parts[{}].carve", i),
            "only sph and dem parts are carved; an fem part's mesh is its shape");
    const auto& names = *cn->as_array();
    for (std::size_t j = 0; j < names.size(); ++j) {
      const std::string name = names.get(j)->as_string()->get();
      const auto it = std::find_if(c.parts.begin(), c.parts.end(),
                                   [&](const PartConfig& q) { return q.name == name; });
      if (it == c.parts.end() || it->name == p.name) {
        error(cw, fmt::format("parts[{}].carve[{}]", i, j),
              it == c.parts.end() ? fmt::format("no part named '{}'", name)
                                  : std::string("a part cannot carve itself"));
        continue;
      }
      p.carve.push_back(static_cast<std::size_t>(it - c.parts.begin()));
    }
  }
}

void Builder::check_overlaps(const Config& c) {
  const int dim = c.dimension;
  auto carves = [&](std::size_t a, std::size_t b) {
    const auto& k = c.parts[a].carve;
    return std::find(k.begin(), k.end(), b) != k.end();
  };

  // A part's mesh from a file: its bounding box is no measure of its body (a ring around a
  // charge), so against a region it overlaps when one of its nodes or element centres lies
  // inside that region by more than a millionth of the region's size; two such meshes (the parts
  // of one file share their interfaces) are not checked against each other.
  auto mesh_of = [&](std::size_t i) -> const mesh::SolidElements* {
    const PartConfig& p = c.parts[i];
    return p.is(Method::Fem) ? p.fem().elements.get() : nullptr;
  };
  auto mesh_in_region = [&](const mesh::SolidElements& m, const RegionConfig& r) {
    Real size = r.radius_m;
    if (r.type == RegionType::Box)
      for (int d = 0; d < dim; ++d)
        size = std::max(
            size, r.max_m[static_cast<std::size_t>(d)] - r.min_m[static_cast<std::size_t>(d)]);
    const Real tol = 1e-6 * size;
    auto inside = [&](const Vec3& x) {
      if (r.type != RegionType::Box) {
        Real s = 0;
        for (int d = 0; d < dim; ++d)
          s += (x[d] - r.center_m[d]) * (x[d] - r.center_m[d]);
        return std::sqrt(s) < r.radius_m - tol;
      }
      for (int d = 0; d < dim; ++d)
        if (!(x[d] > r.min_m[static_cast<std::size_t>(d)] + tol &&
              x[d] < r.max_m[static_cast<std::size_t>(d)] - tol))
          return false;
      return true;
    };
    for (const auto& n : m.nodes)
      if (inside(n)) return true;
    // An element larger than the region may hold it with no node inside: the ball about the
    // element's centre that reaches to the nearest of its faces' centres is inside the element
    // (for the usual, near-convex ones); the region meets the element if it meets that ball.
    const auto npe = static_cast<std::size_t>(m.nodes_per_element);
    const std::vector<std::vector<std::size_t>> faces =
        npe == 8 ? std::vector<std::vector<std::size_t>>{{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                                         {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}}
                 : std::vector<std::vector<std::size_t>>{{0, 1}, {1, 2}, {2, 3}, {3, 0}};
    for (std::size_t e = 0; npe > 0 && e + npe <= m.connectivity.size(); e += npe) {
      auto node = [&](std::size_t k) {
        return m.nodes[static_cast<std::size_t>(m.connectivity[e + k])];
      };
      Vec3 x{0, 0, 0};
      for (std::size_t k = 0; k < npe; ++k)
        for (int d = 0; d < 3; ++d)
          x[d] += node(k)[d] / Real(npe);
      Real reach = std::numeric_limits<Real>::infinity();
      for (const auto& f : faces) {
        Real s = 0;
        for (int d = 0; d < dim; ++d) {
          Real centre = 0;
          for (const std::size_t k : f)
            centre += node(k)[d] / Real(f.size());
          s += (centre - x[d]) * (centre - x[d]);
        }
        reach = std::min(reach, std::sqrt(s));
      }
      if (inside(x) || distance_to_region(x, r, dim) < reach - tol) return true;
    }
    return false;
  };
  auto bodies_overlap = [&](std::size_t a, std::size_t b) {
    const mesh::SolidElements *ma = mesh_of(a), *mb = mesh_of(b);
    if (ma && mb) return false;
    if (ma) return mesh_in_region(*ma, c.parts[b].region);
    if (mb) return mesh_in_region(*mb, c.parts[a].region);
    return overlap(c.parts[a].region, c.parts[b].region, dim);
  };

  // Bodies must not overlap (e.g. the plate "at 0.5 m depth" read as its top face).
  for (std::size_t a = 0; a < c.parts.size(); ++a)
    for (std::size_t b = a + 1; b < c.parts.size(); ++b)
      if (!carves(a, b) && !carves(b, a) && bodies_overlap(a, b)) {
        if (errors_.full()) {
          errors_.suppress();  // counted, not formatted: thousands of parts give millions
          continue;
        }
        error(c.parts[b].region.where, fmt::format("parts[{}].region", b),
              fmt::format("bodies overlap: part '{}' intersects part '{}' (line {})",
                          c.parts[b].name, c.parts[a].name, c.parts[a].region.where.line));
      }
}

RegionConfig Builder::read_region(const toml::table& t, const SourceLocation& w,
                                  const std::string& key, int dim) {
  RegionConfig r;
  r.where = w;
  const std::string type = str(t, "type");
  if (type == "box") {
    r.type = RegionType::Box;
    r.min_m = vec3(t, "min_m");
    r.max_m = vec3(t, "max_m");
    for (int d = 0; d < dim; ++d)
      if (!(r.max_m[d] > r.min_m[d]))
        error(loc(t, "max_m", w), key + ".max_m",
              fmt::format("expected every component above min_m = {}, got {}",
                          vec_text(r.min_m, dim), vec_text(r.max_m, dim)));
  } else if (type == "layer" && !std::isfinite(domain_min_m_[0])) {
    error(loc(t, "type", w), key + ".type",
          "a layer spans the domain: it needs [domain] min_m and max_m");
  } else if (type == "layer") {
    // A horizontal layer across the whole domain: a box from the domain's sides, bottom_m and
    // bottom_m + thickness_m along the vertical axis (y in 2D, z in 3D).
    r.type = RegionType::Box;
    r.min_m = domain_min_m_;
    r.max_m = domain_max_m_;
    const auto up = static_cast<std::size_t>(dim - 1);
    r.min_m[up] = num(t, "bottom_m");
    r.max_m[up] = r.min_m[up] + num(t, "thickness_m");
  } else {
    r.type = type == "disk" ? RegionType::Disk : RegionType::Sphere;
    r.center_m = vec3(t, "center_m");
    r.radius_m = num(t, "radius_m");
    if (type == "disk" && dim != 2)
      error(loc(t, "type", w), key + ".type", "\"disk\" is a 2D region; in 3D use \"sphere\"");
    if (type == "sphere" && dim != 3)
      error(loc(t, "type", w), key + ".type",
            "\"sphere\" is a 3D region; in 2D (plane strain) use \"disk\"");
  }
  return r;
}

// A zone's own lattice: at least two sites across, and not an absurd count.
void Builder::check_zone_spacing(const toml::table& zt, const SourceLocation& zw,
                                 const std::string& key, const ZoneConfig& z, int dim) {
  const Aabb b = bounds(z.region, dim);
  Real min_extent = 1e300;
  for (int d = 0; d < dim; ++d)
    min_extent = std::min(min_extent, b.hi[d] - b.lo[d]);
  if (!(min_extent > 0)) return;  // an inverted region is reported by read_region
  const Real count = volume(z.region, dim) / std::pow(*z.spacing_m, dim);
  if (*z.spacing_m > min_extent / 2)
    error(loc(zt, "spacing_m", zw), key + ".spacing_m",
          fmt::format("expected a spacing below half the zone's smallest extent ({} m), got {} m",
                      min_extent / 2, *z.spacing_m));
  else if (count > kMaxEntities)
    error(loc(zt, "spacing_m", zw), key + ".spacing_m",
          fmt::format("spacing {} m gives about {:.3g} particles in the zone, above the limit of "
                      "{:.0e}",
                      *z.spacing_m, count, kMaxEntities));
}

// The region inside the domain, and a sensible resolution.
void Builder::check_region(const Config& c, const toml::table& t, const toml::table& rt,
                           const SourceLocation& w, const std::string& key, PartConfig& p) {
  const int dim = c.dimension;
  {
    // Inside the domain (when both are well formed: one error per mistake).
    const Aabb b = bounds(p.region, dim);
    bool well_formed = domain_ok_;
    for (int d = 0; d < dim; ++d)
      well_formed = well_formed && b.hi[d] > b.lo[d];
    // An SPH part's region may reach across a plane of symmetry (the charge of a quarter
    // model is the whole sphere, centred on the planes' line): its particles are laid on the
    // modelled side only (parts::region_lattice).
    const auto across = [&](int d, bool upper) {
      return p.is(Method::Sph) &&
             parts::is_symmetry_plane(c.domain, static_cast<parts::Face>(2 * d + (upper ? 1 : 0)));
    };
    for (int d = 0; d < dim && well_formed; ++d)
      if ((b.lo[d] < c.domain.min_m[d] && !across(d, false)) ||
          (b.hi[d] > c.domain.max_m[d] && !across(d, true)) || b.hi[d] <= c.domain.min_m[d] ||
          b.lo[d] >= c.domain.max_m[d]) {
        error(where_of(rt, w), key + ".region",
              fmt::format("expected the region inside the domain {} .. {}{}; it spans {} .. {}",
                          vec_text(c.domain.min_m, dim), vec_text(c.domain.max_m, dim),
                          c.domain.symmetry_planes.empty()
                              ? ""
                              : " (an SPH part's may reach across domain.symmetry_planes)",
                          vec_text(b.lo, dim), vec_text(b.hi, dim)));
        break;
      }

    // Resolution: at least a few particles across, and not an absurd count.
    const Real vol = volume(p.region, dim);
    const Real count = vol / std::pow(p.spacing_m, dim);
    Real min_extent = 1e300;
    for (int d = 0; d < dim; ++d)
      min_extent = std::min(min_extent, b.hi[d] - b.lo[d]);
    if (!(min_extent > 0) || !(p.spacing_m > 0)) {
      // An inverted region was reported above; a missing spacing too.
    } else if (p.is(Method::Fem) ? p.spacing_m > min_extent * (1 + 1e-9)
                                 : p.spacing_m > min_extent / 2)
      error(loc(t, "spacing_m", w), key + ".spacing_m",
            p.is(Method::Fem)
                ? fmt::format("expected an element size at most the region's smallest extent "
                              "({} m), got {} m",
                              min_extent, p.spacing_m)
                : fmt::format("expected a spacing below half the region's smallest extent ({} "
                              "m), got {} m",
                              min_extent / 2, p.spacing_m));
    else if (count > kMaxEntities)
      error(loc(t, "spacing_m", w), key + ".spacing_m",
            fmt::format("spacing {} m gives about {:.3g} particles, above the limit of {:.0e}",
                        p.spacing_m, count, kMaxEntities));
  }
}

std::vector<Face> Builder::read_faces(const toml::array& walls, const SourceLocation& w,
                                      const std::string& key, int dim) {
  std::vector<Face> faces;
  for (std::size_t j = 0; j < walls.size(); ++j) {
    const std::string face = walls.get(j)->as_string()->get();
    const int f = face_index(face);
    if (f / 2 >= dim) {
      error(where_of(*walls.get(j), w), fmt::format("{}[{}]", key, j),
            fmt::format("\"{}\" is a face of the z axis; the scenario is 2D", face));
      continue;
    }
    faces.push_back(static_cast<Face>(f));
  }
  return faces;
}

// A face of a part's walls that is also one of the domain's symmetry planes: the plane holds
// the part already, and two conditions on one face would be ambiguous.
void Builder::check_not_symmetry(const toml::array& walls, const SourceLocation& w,
                                 const std::string& key, const DomainConfig& domain) {
  for (std::size_t j = 0; j < walls.size(); ++j) {
    const int f = face_index(walls.get(j)->as_string()->get());
    if (f < 6 && parts::is_symmetry_plane(domain, static_cast<Face>(f)))
      error(where_of(*walls.get(j), w), fmt::format("{}[{}]", key, j),
            fmt::format("\"{}\" is one of domain.symmetry_planes, which hold every part on "
                        "that face; remove it here",
                        kFaceNames[f]));
  }
}

}  // namespace crater::io::reader
