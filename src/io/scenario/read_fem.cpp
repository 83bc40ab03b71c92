// The scenario reader (reader.hpp): a fem part's [parts.fem]: boundaries, loads, mesh file.
#include <fmt/format.h>
#include <toml++/toml.h>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <variant>

#include "core/file_kind.hpp"
#include "io/scenario/reader.hpp"
#include "io/scenario/schema.hpp"
#include "mesh/gmsh.hpp"
#include "mesh/solid_mesh.hpp"

namespace crater::io::reader {
namespace fs = std::filesystem;

// One initial temperature: the material's room_temperature_k unless the part states its own;
// only a Johnson-Cook material has a temperature.
void Builder::read_initial_temperature(const Config& c, const toml::table& ft,
                                       const SourceLocation& fw, const std::string& key,
                                       PartConfig& p) {
  const auto* jc =
      p.material < c.materials.size()
          ? std::get_if<materials::JohnsonCookParams>(&c.materials[p.material].solid.strength)
          : nullptr;
  const std::optional<Real> t0 = opt_num(ft, "initial_temperature_k");
  if (t0 && !jc) {
    error(loc(ft, "initial_temperature_k", fw), key + ".fem.initial_temperature_k",
          "not used: only a Johnson-Cook material has a temperature (unset it)");
    return;
  }
  // 0 K for a law without temperature: never read.
  p.fem().initial_temperature_k = t0 ? *t0 : jc ? jc->room_temperature_k : Real(0);
  if (t0 && jc && *t0 != jc->room_temperature_k)
    c_warnings_.push_back(fmt::format(
        "part '{}' starts at {} K, not at its material's room_temperature_k = {} K: its "
        "Johnson-Cook T* is {} from the start{}",
        p.name, *t0, jc->room_temperature_k,
        *t0 < jc->room_temperature_k ? "0 (clamped)" : "above 0",
        jc->thermal_softening ? ""
                              : " (it acts only in the damage's D5 term: no thermal_softening)"));
}

void Builder::read_fem(const Config& c, const toml::table& t, const SourceLocation& w,
                       const std::string& key, PartConfig& p) {
  const int dim = c.dimension;
  const auto& ft = table(t, "fem");
  const SourceLocation fw = where_of(ft, w);
  FemConfig& f = p.fem();
  f.hourglass_stiffness = str(ft, "hourglass") == "stiffness";
  f.hourglass_coefficient =
      opt_num(ft, "hourglass_coefficient")
          .value_or(f.hourglass_stiffness ? kHourglassStiffnessDefault : kHourglassViscousDefault);
  f.bulk_viscosity_quadratic = num(ft, "bulk_viscosity_quadratic");
  f.bulk_viscosity_linear = num(ft, "bulk_viscosity_linear");
  read_initial_temperature(c, ft, fw, key, p);
  f.erosion_plastic_strain = opt_num(ft, "erosion_plastic_strain");
  f.erode_inverted = ft.get("erode_inverted")->as_boolean()->get();
  f.erosion_step_ratio = num(ft, "erosion_step_ratio");
  f.mass_scaling_step_ratio = num(ft, "mass_scaling_step_ratio");
  f.mass_scaling_limit = num(ft, "mass_scaling_limit");
  // A solid starts unstressed at its reference density; only velocities can be set.
  const auto& it_init = table(t, "initial");
  for (const char* k : {"density_kg_m3", "pressure_pa"})
    if (it_init.get(k))
      error(loc(it_init, k, w), key + ".initial." + k,
            "not used by fem parts (a solid starts unstressed at the material's rho0_kg_m3)");
  zones_velocity_only(
      t, w, key, "not used by fem parts (zones set the initial velocity of the nodes in them)");
  if (ft.get("mesh_file")) {
    fs::path mesh = str(ft, "mesh_file");
    if (mesh.is_relative()) mesh = fs::path(file_).parent_path() / mesh;
    f.mesh_file = mesh.lexically_normal().string();
    if (ft.get("mesh_group")) f.mesh_group = str(ft, "mesh_group");
  } else if (ft.get("mesh_group")) {
    error(loc(ft, "mesh_group", fw), key + ".fem.mesh_group", "only used with fem.mesh_file");
  }
  if (p.spacing_m > 0 && p.region.type == RegionType::Box) {
    // The structured mesh: whole elements of about spacing_m along each axis.
    for (int d = 0; d < dim; ++d) {
      const Real cells = (p.region.max_m[d] - p.region.min_m[d]) / p.spacing_m;
      if (std::abs(cells - std::round(cells)) > 1e-6 * cells)
        c_warnings_.push_back(
            fmt::format("part '{}': the region's extent along axis {} ({} m) is not a multiple of "
                        "spacing_m = {} m; the elements are stretched to {} whole ones",
                        p.name, d, p.region.max_m[d] - p.region.min_m[d], p.spacing_m,
                        std::max<Real>(1, std::round(cells))));
    }
  }
  if (const toml::node* bn = ft.get("boundary"))
    read_fem_boundaries(*bn->as_array(), fw, key, dim, f);
  if (const toml::node* wn = ft.get("rigid_walls")) {
    const auto& arr = *wn->as_array();
    for (std::size_t k = 0; k < arr.size(); ++k) {
      const auto& wt = *arr.get(k)->as_table();
      const SourceLocation ww = where_of(wt, fw);
      fem::RigidWallSettings r{vec3(wt, "point_m"), vec3(wt, "normal"), num(wt, "friction"), ww};
      Real n2 = 0;
      for (int d = 0; d < dim; ++d)
        n2 += r.normal[static_cast<std::size_t>(d)] * r.normal[static_cast<std::size_t>(d)];
      if (!(n2 > 0))
        error(loc(wt, "normal", ww), fmt::format("{}.fem.rigid_walls[{}].normal", key, k),
              "expected a vector of non-zero length");
      f.rigid_walls.push_back(r);
    }
  }
  if (!f.mesh_file.empty()) read_fem_mesh(c, ft, fw, key, p);
  if (const toml::node* ln = ft.get("loads")) read_fem_loads(*ln->as_array(), fw, key, dim, p);
  if (const toml::node* gn = ft.get("geostatic"))
    read_fem_geostatic(c, *gn->as_table(), fw, key, p);
}

// [parts.fem.geostatic]: the initial stress of a ground at rest (fem/geostatic.hpp). It needs
// gravity along one axis, and a law whose pressure an initial stress can set.
void Builder::read_fem_geostatic(const Config& c, const toml::table& gt, const SourceLocation& fw,
                                 const std::string& key, PartConfig& p) {
  const SourceLocation gw = where_of(gt, fw);
  const std::string gk = key + ".fem.geostatic";
  int axes = 0, axis = 0;
  for (int d = 0; d < c.dimension; ++d)
    if (c.domain.gravity_m_s2[static_cast<std::size_t>(d)] != 0) {
      ++axes;
      axis = d;
    }
  if (axes != 1) {
    error(gw, gk,
          fmt::format("a geostatic stress needs [domain] gravity_m_s2 along exactly one axis, "
                      "got {}",
                      vec_text(c.domain.gravity_m_s2, c.dimension)));
    return;
  }
  if (p.material < c.materials.size() && std::holds_alternative<materials::HolmquistJohnsonCookLaw>(
                                             c.materials[p.material].solid.strength)) {
    error(gw, gk,
          "not for holmquist_johnson_cook materials: their pressure follows from the density "
          "(the compaction EOS), so an initial stress would not hold");
    return;
  }
  GeostaticConfig g;
  g.surface_m = num(gt, "surface_m");
  g.k0 = opt_num(gt, "k0");
  p.fem().geostatic = g;
  if (p.region.type != RegionType::Box) return;
  // Depths of the part's two extents on gravity's axis: a part wholly above the surface stays
  // unstressed; one whose top lies below it misses the overburden (not in equilibrium).
  const auto u = static_cast<std::size_t>(axis);
  const Real down = c.domain.gravity_m_s2[u] < 0 ? -1 : 1;
  const Real d_lo = (p.region.min_m[u] - g.surface_m) * down;
  const Real d_hi = (p.region.max_m[u] - g.surface_m) * down;
  const Real tol = 1e-9 * (p.region.max_m[u] - p.region.min_m[u]);
  if (std::max(d_lo, d_hi) <= tol)
    c_warnings_.push_back(fmt::format(
        "part '{}': fem.geostatic.surface_m = {} m lies below the whole part, which starts "
        "unstressed",
        p.name, g.surface_m));
  else if (std::min(d_lo, d_hi) > tol)
    c_warnings_.push_back(fmt::format(
        "part '{}': fem.geostatic.surface_m = {} m lies above the part's top ({} m deep): the "
        "overburden is not there, and the top is not in equilibrium (a pressure load of "
        "rho0 g x that depth on it would stand for the overburden)",
        p.name, g.surface_m, std::min(d_lo, d_hi)));
}

// [[parts.fem.boundary]]: a face of the part's box or a group of its mesh file, and what is
// imposed there.
void Builder::read_fem_boundaries(const toml::array& ba, const SourceLocation& fw,
                                  const std::string& key, int dim, FemConfig& f) {
  for (std::size_t j = 0; j < ba.size(); ++j) {
    const auto& bt = *ba.get(j)->as_table();
    const SourceLocation bw = where_of(bt, fw);
    const std::string bk = fmt::format("{}.fem.boundary[{}]", key, j);
    FemBoundaryConfig b;
    b.where = bw;
    const std::string type = str(bt, "type");
    b.type = type == "fixed"      ? FemBoundaryType::Fixed
             : type == "symmetry" ? FemBoundaryType::Symmetry
             : type == "velocity" ? FemBoundaryType::Velocity
                                  : FemBoundaryType::NonReflecting;
    const bool has_face = bt.get("face") != nullptr, has_group = bt.get("group") != nullptr;
    if (has_face == has_group) {
      error(bw, bk, "expected exactly one of face or group");
      continue;
    }
    if (has_face) {
      const std::string face = str(bt, "face");
      const int fi = face_index(face);
      if (fi / 2 >= dim) {
        error(loc(bt, "face", bw), bk + ".face",
              fmt::format("\"{}\" is a face of the z axis; the scenario is 2D", face));
        continue;
      }
      b.face = static_cast<Face>(fi);
    } else {
      b.group = str(bt, "group");
      if (f.mesh_file.empty())
        error(loc(bt, "group", bw), bk + ".group",
              "mesh groups need fem.mesh_file; on a structured mesh give face");
    }
    if (bt.get("velocity_m_s") || bt.get("components")) {
      if (b.type != FemBoundaryType::Velocity)
        error(loc(bt, bt.get("velocity_m_s") ? "velocity_m_s" : "components", bw),
              bk + (bt.get("velocity_m_s") ? ".velocity_m_s" : ".components"),
              "only used by type = \"velocity\"");
      b.velocity_m_s = vec3(bt, "velocity_m_s");
      if (const toml::node* cn = bt.get("components")) {
        b.components = {false, false, false};
        for (const auto& e : *cn->as_array()) {
          const std::string axis = e.as_string()->get();
          const int a = axis[0] - 'x';
          if (a >= dim)
            error(where_of(e, bw), bk + ".components", "\"z\" is not a component of a 2D scenario");
          else
            b.components[static_cast<std::size_t>(a)] = true;
        }
      }
    }
    f.boundaries.push_back(b);
  }
}

// [[parts.fem.loads]]: a face of the part's box, an optional box on it, a pressure table.
void Builder::read_fem_loads(const toml::array& la, const SourceLocation& fw,
                             const std::string& key, int dim, PartConfig& p) {
  for (std::size_t j = 0; j < la.size(); ++j) {
    const auto& lt = *la.get(j)->as_table();
    const SourceLocation lw = where_of(lt, fw);
    const std::string lk = fmt::format("{}.fem.loads[{}]", key, j);
    FemLoadConfig l;
    l.where = lw;
    l.type = FemLoadType::Pressure;
    if ((lt.get("face") != nullptr) == (lt.get("group") != nullptr)) {
      error(lw, lk, "expected exactly one of face or group");
      continue;
    }
    if (lt.get("group")) {
      l.group = str(lt, "group");
      const auto& mesh = p.fem().elements;
      if (p.fem().mesh_file.empty() || lt.get("region")) {
        error(loc(lt, "group", lw), lk + ".group",
              p.fem().mesh_file.empty()
                  ? "mesh groups need fem.mesh_file; on a structured mesh give face"
                  : "a load on a group takes all its faces: region is only used with face");
        continue;
      }
      if (mesh && !mesh->groups.count(l.group)) {
        std::string known;
        for (const auto& [name, g] : mesh->groups)
          known += (known.empty() ? "'" : ", '") + name + "'";
        error(loc(lt, "group", lw), lk + ".group",
              fmt::format("no physical group '{}' with nodes of the part in {} (groups: {})",
                          l.group, p.fem().mesh_file, known.empty() ? "none" : known));
        continue;
      }
    }
    const std::string face = l.group.empty() ? str(lt, "face") : "left";
    const int fi = face_index(face);
    if (fi / 2 >= dim) {
      error(loc(lt, "face", lw), lk + ".face",
            fmt::format("\"{}\" is a face of the z axis; the scenario is 2D", face));
      continue;
    }
    l.face = static_cast<Face>(fi);
    const int normal = fi / 2;
    if (const toml::node* rn = lt.get("region")) {
      const auto& rt = *rn->as_table();
      const SourceLocation rw = where_of(rt, lw);
      if (str(rt, "type") != "box") {
        error(loc(rt, "type", rw), lk + ".region.type",
              "expected \"box\": a load selects the faces whose centre lies in a box");
        continue;
      }
      l.region = read_region(rt, rw, lk + ".region", dim);
      // The box must meet the part's face (along the axes other than the face normal).
      if (p.region.type == RegionType::Box)
        for (int d = 0; d < dim; ++d) {
          const auto u = static_cast<std::size_t>(d);
          if (d == normal) continue;
          if (!(l.region->max_m[u] > p.region.min_m[u] && l.region->min_m[u] < p.region.max_m[u]))
            error(loc(rt, "min_m", rw), lk + ".region",
                  fmt::format("the box ({} .. {}) does not meet the part's {} face, which spans "
                              "{} .. {}",
                              vec_text(l.region->min_m, dim), vec_text(l.region->max_m, dim), face,
                              vec_text(p.region.min_m, dim), vec_text(p.region.max_m, dim)));
        }
    }
    l.time_s = reals(lt, "time_s");
    l.pressure_pa = reals(lt, "pressure_pa");
    const SourceLocation tw = loc(lt, "time_s", lw);
    if (l.time_s.size() < 2 || l.time_s.size() != l.pressure_pa.size()) {
      error(tw, lk + ".time_s",
            fmt::format("expected time_s and pressure_pa of the same length, at least 2, got "
                        "{} and {}",
                        l.time_s.size(), l.pressure_pa.size()));
      continue;
    }
    bool ok = true;
    for (std::size_t q = 0; q < l.time_s.size(); ++q)
      if (!std::isfinite(l.time_s[q]) || (q > 0 && !(l.time_s[q] > l.time_s[q - 1]))) {
        error(tw, fmt::format("{}.time_s[{}]", lk, q),
              fmt::format("expected finite times in strictly increasing order, got {} s after "
                          "{} s",
                          l.time_s[q], q > 0 ? l.time_s[q - 1] : l.time_s[q]));
        ok = false;
        break;
      }
    for (std::size_t q = 0; q < l.pressure_pa.size(); ++q)
      if (!std::isfinite(l.pressure_pa[q])) {
        error(loc(lt, "pressure_pa", lw), fmt::format("{}.pressure_pa[{}]", lk, q),
              "expected a finite pressure");
        ok = false;
      }
    if (ok) p.fem().loads.push_back(l);
  }
}

// Mesh files are read when the scenario is, so that a malformed mesh is an input error
// (exit 2) before anything runs; the part is built from the elements taken from it here
// (a degenerate element is found then: still an input error, at `crater check` too).
void Builder::read_fem_mesh(const Config& c, const toml::table& ft, const SourceLocation& fw,
                            const std::string& key, PartConfig& p) {
  FemConfig& f = p.fem();
  const SourceLocation mw = loc(ft, "mesh_file", fw);
  std::error_code ec;
  if (!fs::is_regular_file(f.mesh_file, ec)) {
    const std::string kind = not_a_regular_file(f.mesh_file);
    error(mw, key + ".fem.mesh_file",
          fmt::format("expected a Gmsh .msh file; '{}' {}", f.mesh_file,
                      !kind.empty()                 ? kind
                      : fs::exists(f.mesh_file, ec) ? "cannot be read"
                                                    : "does not exist"));
    return;
  }
  try {
    f.elements = std::make_shared<const mesh::SolidElements>(
        mesh::solid_elements(mesh::read_gmsh(f.mesh_file), f.mesh_file, f.mesh_group, c.dimension));
    const std::array<Real, 3> lo = f.elements->lo, hi = f.elements->hi;
    // The mesh's bounding box stands for the region: inside the domain, not overlapping.
    p.region.type = RegionType::Box;
    p.region.min_m = lo;
    p.region.max_m = hi;
    p.region.where = mw;
    for (int d = 0; d < c.dimension; ++d)
      if (lo[static_cast<std::size_t>(d)] < c.domain.min_m[static_cast<std::size_t>(d)] ||
          hi[static_cast<std::size_t>(d)] > c.domain.max_m[static_cast<std::size_t>(d)]) {
        error(mw, key + ".fem.mesh_file",
              fmt::format("expected the mesh inside the domain {} .. {}; it spans {} .. {}",
                          vec_text(c.domain.min_m, c.dimension),
                          vec_text(c.domain.max_m, c.dimension), vec_text(lo, c.dimension),
                          vec_text(hi, c.dimension)));
        break;
      }
    for (std::size_t j = 0; j < f.boundaries.size(); ++j) {
      const auto& b = f.boundaries[j];
      if (b.group.empty()) continue;
      if (const auto g = f.elements->groups.find(b.group); g != f.elements->groups.end()) {
        if (b.type == FemBoundaryType::Symmetry && g->second.normal_axis < 0)
          error(b.where, fmt::format("{}.fem.boundary[{}].group", key, j),
                fmt::format("a symmetry condition needs a plane normal to x, y{}; the nodes of "
                            "group '{}' are not on one",
                            c.dimension == 3 ? " or z" : "", b.group));
        continue;
      }
      std::string known;
      for (const auto& [name, g] : f.elements->groups)
        known += (known.empty() ? "'" : ", '") + name + "'";
      error(b.where, fmt::format("{}.fem.boundary[{}].group", key, j),
            fmt::format("no physical group '{}' with nodes of the part in {} (groups: {})", b.group,
                        f.mesh_file, known.empty() ? "none" : known));
    }
  } catch (const InputError& e) {
    // The reader names the file and line of the mesh; the key is the scenario's (the group
    // when the part names one and the reader found none of its elements).
    if (!e.key().empty())
      errors_.add(e);
    else if (!f.mesh_group.empty() && std::string(e.what()).find("in group '") != std::string::npos)
      error(loc(ft, "mesh_group", fw), key + ".fem.mesh_group", e.what());
    else
      error(e.where(), key + ".fem.mesh_file", e.what());
  }
}

}  // namespace crater::io::reader
