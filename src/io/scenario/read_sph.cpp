// The scenario reader (reader.hpp): an sph part's [parts.sph] (walls and their dummy
// particles) and its detonation points.
#include <fmt/format.h>
#include <toml++/toml.h>
#include <algorithm>
#include <cmath>
#include <limits>

#include "io/scenario/reader.hpp"

namespace crater::io::reader {

void Builder::read_sph(const Config& c, const toml::table& t, const SourceLocation& w,
                       const std::string& key, PartConfig& p) {
  const int dim = c.dimension;
  const auto& st = table(t, "sph");
  SphConfig& s = p.sph();
  s.kernel = str(st, "kernel") == "cubic_spline" ? sph::KernelKind::CubicSpline
                                                 : sph::KernelKind::WendlandC2;
  s.density = str(st, "density") == "summation" ? sph::DensityKind::Summation
                                                : sph::DensityKind::Continuity;
  s.h_factor = num(st, "h_factor");
  s.av_alpha = num(st, "av_alpha");
  s.av_beta = num(st, "av_beta");
  s.cfl = num(st, "cfl");
  s.variable_h = st.get("variable_h")->as_boolean()->get();
  s.xsph_epsilon = num(st, "xsph_epsilon");
  s.tensile_epsilon = num(st, "tensile_epsilon");
  s.viscosity_pa_s = num(st, "viscosity_pa_s");
  s.conductivity_alpha = num(st, "conductivity_alpha");
  s.wall_layers = static_cast<int>(st.get("wall_layers")->as_integer()->get());
  s.wall_no_slip = str(st, "wall_slip") == "no";
  s.walls = read_faces(*st.get("walls")->as_array(), w, key + ".sph.walls", dim);
  check_not_symmetry(*st.get("walls")->as_array(), w, key + ".sph.walls", c.domain);
  if (s.wall_no_slip && !s.walls.empty() && !c.domain.symmetry_planes.empty())
    error(loc(st, "wall_slip", w), key + ".sph.wall_slip",
          "no-slip walls (dummy particles) cannot be combined with the domain's "
          "symmetry_planes (mirror images); use wall_slip = \"free\", or model the whole "
          "domain");
  for (const Face f : s.walls) {
    // The wall lattice is laid at the part's spacing along the face: the domain's extent
    // along the face's other axes should be a multiple of it, or gaps open at the far end.
    for (int d = 0; d < dim; ++d) {
      if (d == static_cast<int>(f) / 2) continue;
      const Real n = (c.domain.max_m[d] - c.domain.min_m[d]) / p.spacing_m;
      if (std::abs(n - std::round(n)) > 1e-6 * n)
        c_warnings_.push_back(
            fmt::format("part '{}': the domain extent along axis {} ({} m) is not a multiple of "
                        "spacing_m = {} m; the {} wall's particles leave a gap at the far end",
                        p.name, d, c.domain.max_m[d] - c.domain.min_m[d], p.spacing_m,
                        kFaceNames[static_cast<int>(f)]));
    }
  }
  if (s.wall_no_slip && !s.walls.empty() && p.spacing_m > 0) {
    // Dummy particles fill every walled face over the whole domain, as deep as the kernel
    // support of the largest particle (the coarsest lattice: part or zone).
    Real coarsest = p.spacing_m;
    for (const auto& z : p.zones)
      if (z.spacing_m) coarsest = std::max(coarsest, *z.spacing_m);
    const Real layers =
        std::max<Real>(s.wall_layers, std::ceil(2 * s.h_factor * coarsest / p.spacing_m));
    Real count = 0;
    for (Face f : s.walls) {
      Real n = layers;
      for (int d = 0; d < dim; ++d)
        if (d != static_cast<int>(f) / 2)
          n *=
              std::max<Real>(1, (c.domain.max_m[d] - c.domain.min_m[d]) / p.spacing_m + 2 * layers);
      count += n;
    }
    p.estimated_wall_count = count;
    if (count > kMaxEntities)
      error(loc(st, "walls", w), key + ".sph.walls",
            fmt::format("no-slip walls along the whole domain need about {:.3g} wall particles at "
                        "spacing_m = {} m, above the limit of {:.0e}: shrink [domain] to the "
                        "fluid's reach or coarsen the spacing",
                        count, p.spacing_m, kMaxEntities));
  }
  if (const toml::node* dn = t.get("detonation")) read_detonations(c, *dn->as_array(), w, key, p);
}

// A plane's normal or a line's direction, made a unit vector; false (an error given) when the
// shape's vector is missing, zero, or given to another shape.
bool Builder::read_initiator(const toml::table& dtab, const SourceLocation& dw,
                             const std::string& dkey, int dim, DetonationPoint& dp) {
  const std::string shape = str(dtab, "shape");
  dp.shape = shape == "plane"  ? parts::Initiator::Plane
             : shape == "line" ? parts::Initiator::Line
                               : parts::Initiator::Point;
  const char* wanted = dp.shape == parts::Initiator::Plane  ? "normal"
                       : dp.shape == parts::Initiator::Line ? "direction"
                                                            : nullptr;
  for (const char* k : {"normal", "direction"})
    if (dtab.get(k) && (wanted == nullptr || std::string(k) != wanted)) {
      error(loc(dtab, k, dw), dkey + "." + k,
            fmt::format("not used with shape = \"{}\"{}", shape,
                        wanted ? fmt::format(" (it takes {})", wanted) : std::string()));
      return false;
    }
  if (!wanted) return true;
  if (!dtab.get(wanted)) {
    error(dw, dkey + "." + wanted, fmt::format("missing: shape = \"{}\" needs {}", shape, wanted));
    return false;
  }
  const Vec3 a = vec3(dtab, wanted);
  Real n2 = 0;
  for (int d = 0; d < dim; ++d)
    n2 += a[static_cast<std::size_t>(d)] * a[static_cast<std::size_t>(d)];
  if (!(n2 > 0)) {
    error(loc(dtab, wanted, dw), dkey + "." + wanted, "expected a vector of non-zero length");
    return false;
  }
  for (int d = 0; d < dim; ++d)
    dp.axis[static_cast<std::size_t>(d)] = a[static_cast<std::size_t>(d)] / std::sqrt(n2);
  return true;
}

// Whether a plane (its signed distances to the box's corners change sign or vanish) or a line
// (within half the box's diagonal of its centre) meets the box.
bool Builder::initiator_meets_box(const DetonationPoint& dp, const Aabb& b, int dim) {
  Real lo = std::numeric_limits<Real>::infinity(), hi = -lo, diag2 = 0, r2 = 0, along = 0;
  for (int corner = 0; corner < (1 << dim); ++corner) {
    Real s = 0;
    for (int d = 0; d < dim; ++d) {
      const Real x = (corner >> d) & 1 ? b.hi[d] : b.lo[d];
      s += (x - dp.point_m[static_cast<std::size_t>(d)]) * dp.axis[static_cast<std::size_t>(d)];
    }
    lo = std::min(lo, s), hi = std::max(hi, s);
  }
  if (dp.shape == parts::Initiator::Plane) return lo <= 0 && hi >= 0;
  for (int d = 0; d < dim; ++d) {
    const auto u = static_cast<std::size_t>(d);
    const Real c = 0.5 * (b.lo[d] + b.hi[d]) - dp.point_m[u];
    diag2 += 0.25 * (b.hi[d] - b.lo[d]) * (b.hi[d] - b.lo[d]);
    r2 += c * c;
    along += c * dp.axis[u];
  }
  return r2 - along * along <= diag2;
}

// [[parts.detonation]]: points of a JWL charge, inside the domain and the charge.
void Builder::read_detonations(const Config& c, const toml::array& da, const SourceLocation& w,
                               const std::string& key, PartConfig& p) {
  const int dim = c.dimension;
  const bool jwl = p.material < c.materials.size() && c.materials[p.material].model == "jwl";
  for (std::size_t j = 0; j < da.size(); ++j) {
    const auto& dtab = *da.get(j)->as_table();
    DetonationPoint dp;
    dp.point_m = vec3(dtab, "point_m");
    dp.time_s = num(dtab, "time_s");
    const SourceLocation dw = where_of(dtab, w);
    const std::string dkey = fmt::format("{}.detonation[{}]", key, j);
    if (!read_initiator(dtab, dw, dkey, dim, dp)) continue;
    if (!jwl)
      error(dw, fmt::format("{}.detonation[{}]", key, j),
            "detonation points need a JWL material (the part's material is not \"jwl\")");
    bool in_domain = true;
    for (int d = 0; d < dim; ++d)
      if (dp.point_m[d] < c.domain.min_m[d] || dp.point_m[d] > c.domain.max_m[d]) {
        error(loc(dtab, "point_m", dw), fmt::format("{}.detonation[{}].point_m", key, j),
              "expected a point inside the domain, got " + vec_text(dp.point_m, dim));
        in_domain = false;
        break;
      }
    // A point outside the charge lights it only when the front, run through the empty
    // space between, arrives: late, and from the wrong place. A point on the boundary
    // (to rounding, relative to the region's size) is a surface initiation and is kept.
    const Aabb rb = bounds(p.region, dim);
    Real size = 0;
    for (int d = 0; d < dim; ++d)
      size = std::max(size, rb.hi[d] - rb.lo[d]);
    const Real outside = distance_to_region(dp.point_m, p.region, dim);
    if (dp.shape != parts::Initiator::Point) {
      // A plane or line must meet the charge's bounding box.
      if (in_domain && size > 0 && !initiator_meets_box(dp, rb, dim))
        error(loc(dtab, "point_m", dw), dkey,
              fmt::format("the {} through {} misses the charge (part '{}': {})",
                          dp.shape == parts::Initiator::Plane ? "plane" : "line",
                          vec_text(dp.point_m, dim), p.name, region_text(p.region, dim)));
    } else if (in_domain && size > 0 && outside > 1e-6 * size)
      error(loc(dtab, "point_m", dw), fmt::format("{}.detonation[{}].point_m", key, j),
            fmt::format("expected a point inside the charge's region (part '{}': {}; its "
                        "boundary included); it is at {}, {:.3g} m outside",
                        p.name, region_text(p.region, dim), vec_text(dp.point_m, dim), outside));
    p.detonations.push_back(dp);
  }
}

}  // namespace crater::io::reader
