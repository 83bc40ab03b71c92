// The scenario reader (reader.hpp): a dem part's [parts.dem], packing, absorbing walls, bonds and
// grains placed by hand.
#include <fmt/format.h>
#include <toml++/toml.h>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "io/scenario/reader.hpp"

namespace crater::io::reader {
namespace fs = std::filesystem;

void Builder::read_dem(const Config& c, const toml::table& t, const SourceLocation& w,
                       const std::string& key, PartConfig& p) {
  const int dim = c.dimension;
  const auto& dt = table(t, "dem");
  const SourceLocation dw = where_of(dt, w);
  DemConfig& d = p.dem();
  read_packing(c, t, w, key, p);
  zones_velocity_only(t, w, key,
                      "not used by dem parts (zones set the initial velocity of the grains whose "
                      "centres are in them)");
  d.radius_max_m = opt_num(dt, "radius_max_m").value_or(0.5 * p.spacing_m);
  d.radius_min_m = opt_num(dt, "radius_min_m").value_or(d.radius_max_m);
  if (p.packing().method == dem::PackingMethod::Lattice && !t.get("particles") &&
      d.radius_max_m > 0.5 * p.spacing_m * (1 + 1e-12))
    error(loc(dt, "radius_max_m", dw), key + ".dem.radius_max_m",
          fmt::format("expected at most spacing_m / 2 = {} m (grains sit on a lattice of "
                      "pitch spacing_m), got {} m",
                      0.5 * p.spacing_m, d.radius_max_m));
  if (d.radius_min_m > d.radius_max_m)
    error(loc(dt, "radius_min_m", dw), key + ".dem.radius_min_m",
          fmt::format("expected at most radius_max_m = {} m, got {} m", d.radius_max_m,
                      d.radius_min_m));
  d.seed = static_cast<std::uint64_t>(dt.get("seed")->as_integer()->get());
  d.local_damping = num(dt, "local_damping");
  d.rayleigh_fraction = num(dt, "rayleigh_fraction");
  d.walls = read_faces(*dt.get("walls")->as_array(), dw, key + ".dem.walls", dim);
  check_not_symmetry(*dt.get("walls")->as_array(), dw, key + ".dem.walls", c.domain);
  d.wall_friction = num(dt, "wall_friction");
  d.wall_restitution = num(dt, "wall_restitution");
  d.contact =
      str(dt, "contact") == "linear_spring" ? DemContact::LinearSpring : DemContact::HertzMindlin;
  d.stiffness_step_fraction = num(dt, "stiffness_step_fraction");
  d.hertz_row_of_spheres = str(dt, "hertz_2d") == "row_of_spheres";
  if (d.contact == DemContact::LinearSpring) {
    if (const auto kn = opt_num(dt, "normal_stiffness_n_m")) {
      d.normal_stiffness_n_m = *kn;
      // Mindlin's ratio of tangential to normal stiffness of equal grains.
      const Real nu = p.material < c.materials.size()
                          ? c.materials[p.material].granular.poisson_ratio
                          : Real(0);
      d.shear_stiffness_n_m =
          opt_num(dt, "shear_stiffness_n_m").value_or(*kn * 2 * (1 - nu) / (2 - nu));
    } else {
      error(loc(dt, "contact", dw), key + ".dem.normal_stiffness_n_m",
            "missing: contact = \"linear_spring\" needs normal_stiffness_n_m (N/m)");
    }
  } else {
    for (const char* k : {"normal_stiffness_n_m", "shear_stiffness_n_m"})
      if (dt.get(k))
        error(loc(dt, k, dw), key + ".dem." + k,
              "only used by contact = \"linear_spring\"; the Hertz-Mindlin stiffness "
              "follows from the material");
  }
  d.rolling_friction = num(dt, "rolling_friction");
  d.rolling_damping = num(dt, "rolling_damping");
  d.rate_dependent_friction = dt.get("rate_dependent_friction")->as_boolean()->get();
  d.friction_rate_beta = num(dt, "friction_rate_beta");
  d.friction_reference_strain_rate = num(dt, "friction_reference_strain_rate");
  read_absorbing_walls(dt, dw, key, dim, c.domain, d);
  read_bonds(table(dt, "bonds"), dw, key, d.bonds);
  if (const toml::node* mn = dt.get("wall_motion"))
    read_wall_motion(c, *mn->as_array(), dw, key, d);
  if (const toml::node* pn = t.get("particles")) {
    read_particles(c, *pn->as_array(), w, key, p);
    // The radius range, unless given, is the placed grains' (no lattice to size it).
    if (!d.particles.empty()) {
      const auto [lo, hi] = std::minmax_element(
          d.particles.begin(), d.particles.end(),
          [](const DemParticle& a, const DemParticle& b) { return a.radius_m < b.radius_m; });
      if (!dt.get("radius_max_m")) d.radius_max_m = hi->radius_m;
      if (!dt.get("radius_min_m")) d.radius_min_m = lo->radius_m;
    }
  }
}

// [parts.dem.bonds]: parallel bonds; their stiffness and strengths are needed when enabled.
void Builder::read_bonds(const toml::table& bt, const SourceLocation& dw, const std::string& key,
                         DemBondConfig& b) {
  const SourceLocation bw = where_of(bt, dw);
  b.enabled = bt.get("enabled")->as_boolean()->get();
  const std::string rule = str(bt, "radius_rule");
  b.radius_rule = rule == "mean"        ? BondRadius::Mean
                  : rule == "effective" ? BondRadius::Effective
                                        : BondRadius::Min;
  b.radius_multiplier = num(bt, "radius_multiplier");
  b.gap_fraction = num(bt, "gap_fraction");
  if (b.enabled) {
    const std::string kb = key + ".dem.bonds.";
    auto need = [&](const char* name, Real& into) {
      if (const auto v = opt_num(bt, name))
        into = *v;
      else
        error(loc(bt, "enabled", bw), kb + name, "missing: bonds need it when enabled");
    };
    need("normal_stiffness_pa_m", b.normal_stiffness_pa_m);
    need("tensile_strength_pa", b.tensile_strength_pa);
    need("shear_strength_pa", b.shear_strength_pa);
    b.shear_stiffness_pa_m = opt_num(bt, "shear_stiffness_pa_m").value_or(b.normal_stiffness_pa_m);
  }
}

// [[parts.dem.wall_motion]]: which of the part's rigid walls move, and how (velocity or servo
// stress, one of the two); a face's entries in windows apart; the starting position inside the
// domain.
void Builder::read_wall_motion(const Config& c, const toml::array& ma, const SourceLocation& dw,
                               const std::string& key, DemConfig& d) {
  for (std::size_t j = 0; j < ma.size(); ++j) {
    const auto& mt = *ma.get(j)->as_table();
    const SourceLocation mw = where_of(mt, dw);
    const std::string mk = fmt::format("{}.dem.wall_motion[{}]", key, j);
    dem::WallMotion m;
    const std::string face = str(mt, "face");
    const int fi = face_index(face);
    m.face = static_cast<Face>(fi);
    if (fi / 2 >= c.dimension) {
      error(loc(mt, "face", mw), mk + ".face",
            fmt::format("\"{}\" is a face of the z axis; the scenario is 2D", face));
      continue;
    }
    if (std::find(d.walls.begin(), d.walls.end(), m.face) == d.walls.end()) {
      error(loc(mt, "face", mw), mk + ".face",
            fmt::format("\"{}\" is not one of {}.dem.walls: only a rigid wall of the part can "
                        "move",
                        face, key));
      continue;
    }
    const auto velocity = opt_num(mt, "velocity_m_s");
    const auto stress = opt_num(mt, "stress_pa");
    if (velocity.has_value() == stress.has_value())
      error(mw, mk + (velocity ? ".stress_pa" : ".velocity_m_s"),
            velocity ? "give velocity_m_s or stress_pa, not both"
                     : "missing: give velocity_m_s (a constant speed) or stress_pa (a servo "
                       "target)");
    m.drive = stress ? dem::WallDrive::Stress : dem::WallDrive::Velocity;
    m.velocity_m_s = velocity.value_or(0);
    m.ramp_s = num(mt, "ramp_s");
    m.stress_pa = stress.value_or(0);
    m.servo_gain = num(mt, "servo_gain");
    m.max_speed_m_s = num(mt, "max_speed_m_s");
    m.start_s = num(mt, "start_s");
    m.end_s = opt_num(mt, "end_s").value_or(std::numeric_limits<Real>::infinity());
    if (!(m.end_s > m.start_s))
      error(loc(mt, "end_s", mw), mk + ".end_s",
            fmt::format("expected after start_s = {} s, got {} s", m.start_s, m.end_s));
    // Entries of one face take turns: their windows do not overlap; one gives its position.
    for (const dem::WallMotion& o : d.wall_motion) {
      if (o.face != m.face) continue;
      if (m.start_s < o.end_s && o.start_s < m.end_s)
        error(loc(mt, "start_s", mw), mk + ".start_s",
              fmt::format("the wall \"{}\" already moves from {} s to {} s (an earlier entry); "
                          "a face's entries need windows [start_s, end_s) apart",
                          face, o.start_s, o.end_s));
      if (o.position_m && mt.get("position_m"))
        error(loc(mt, "position_m", mw), mk + ".position_m",
              fmt::format("an earlier entry of \"{}\" gives its position already", face));
    }
    m.position_m = opt_num(mt, "position_m");
    const auto axis = static_cast<std::size_t>(fi / 2);
    if (m.position_m &&
        !(*m.position_m >= c.domain.min_m[axis] && *m.position_m <= c.domain.max_m[axis]))
      error(loc(mt, "position_m", mw), mk + ".position_m",
            fmt::format("expected inside the domain, [{}, {}] m, got {} m", c.domain.min_m[axis],
                        c.domain.max_m[axis], *m.position_m));
    d.wall_motion.push_back(m);
  }
}

// [[parts.particles]]: grains placed by hand, inside the domain.
void Builder::read_particles(const Config& c, const toml::array& pa, const SourceLocation& w,
                             const std::string& key, PartConfig& p) {
  const int dim = c.dimension;
  for (std::size_t j = 0; j < pa.size(); ++j) {
    const auto& pt = *pa.get(j)->as_table();
    DemParticle q;
    q.center_m = vec3(pt, "center_m");
    q.radius_m = num(pt, "radius_m");
    q.velocity_m_s = vec3(pt, "velocity_m_s");
    for (int d = 0; d < dim; ++d)
      if (q.center_m[d] < c.domain.min_m[d] || q.center_m[d] > c.domain.max_m[d]) {
        error(loc(pt, "center_m", where_of(pt, w)),
              fmt::format("{}.particles[{}].center_m", key, j),
              "expected the grain inside the domain, got centre " + vec_text(q.center_m, dim) +
                  fmt::format(" and radius {} m", q.radius_m));
        break;
      }
    p.dem().particles.push_back(q);
  }
}

void Builder::read_packing(const Config& c, const toml::table& t, const SourceLocation& w,
                           const std::string& key, PartConfig& p) {
  const auto& pt = table(t, "packing");
  const SourceLocation pw = where_of(pt, w);
  PackingConfig& k = p.packing();
  const std::string method = str(pt, "method");
  k.method = method == "random"  ? dem::PackingMethod::Random
             : method == "dense" ? dem::PackingMethod::Dense
                                 : dem::PackingMethod::Lattice;
  k.settle = pt.get("settle")->as_boolean()->get();
  k.settle_unbalanced_ratio = num(pt, "settle_unbalanced_ratio");
  k.settle_kinetic_ratio = num(pt, "settle_kinetic_ratio");
  k.settle_max_time_s = num(pt, "settle_max_time_s");
  k.settle_damping = num(pt, "settle_damping");
  k.settle_safety_factor = opt_num(pt, "settle_safety_factor").value_or(0);
  k.agitation_m_s = num(pt, "agitation_m_s");
  fs::path cache = str(pt, "cache_dir");
  if (cache.is_relative()) cache = fs::path(file_).parent_path() / cache;
  k.cache_dir = cache.lexically_normal().string();
  const std::string kp = key + ".packing";
  if (k.method == dem::PackingMethod::Random) {
    if (!pt.get("porosity"))
      error(pw, kp + ".porosity", "missing: method = \"random\" needs a target porosity");
    else
      k.porosity = num(pt, "porosity");
  }
  if (k.method != dem::PackingMethod::Lattice && t.get("particles"))
    error(loc(t, "particles", w), key + ".particles",
          fmt::format("grains placed by hand cannot also be packed; remove one of [[{}.particles]] "
                      "and [{}] method = \"{}\"",
                      key, kp, method));
  if (k.method == dem::PackingMethod::Dense) read_dense_packing(c, pt, pw, kp, p);
  k.sieve_diameter_m = reals(pt, "sieve_diameter_m");
  k.sieve_passing = reals(pt, "sieve_passing");
  if (!k.sieve_diameter_m.empty() || !k.sieve_passing.empty()) {
    const SourceLocation sw = loc(pt, "sieve_diameter_m", pw);
    if (k.method != dem::PackingMethod::Random)
      error(sw, kp + ".sieve_diameter_m", "a grading curve needs method = \"random\"");
    if (k.sieve_diameter_m.size() != k.sieve_passing.size() || k.sieve_diameter_m.size() < 2)
      error(sw, kp + ".sieve_diameter_m",
            fmt::format("expected sieve_diameter_m and sieve_passing of the same length, at "
                        "least 2, got {} and {}",
                        k.sieve_diameter_m.size(), k.sieve_passing.size()));
    for (std::size_t j = 0; j < k.sieve_diameter_m.size(); ++j) {
      if (!(k.sieve_diameter_m[j] > 0) ||
          (j > 0 && !(k.sieve_diameter_m[j] > k.sieve_diameter_m[j - 1])))
        error(sw, fmt::format("{}.sieve_diameter_m[{}]", kp, j),
              fmt::format("expected positive diameters in ascending order, got {} m",
                          k.sieve_diameter_m[j]));
    }
    for (std::size_t j = 0; j < k.sieve_passing.size(); ++j) {
      const Real f = k.sieve_passing[j];
      if (!(f >= 0 && f <= 1) || (j > 0 && !(f >= k.sieve_passing[j - 1])))
        error(loc(pt, "sieve_passing", pw), fmt::format("{}.sieve_passing[{}]", kp, j),
              fmt::format("expected fractions in [0, 1], non-decreasing, got {}", f));
    }
    if (!k.sieve_passing.empty() && k.sieve_passing.back() != 1.0)
      error(loc(pt, "sieve_passing", pw), kp + ".sieve_passing",
            fmt::format("expected the last sieve to pass everything (1), got {}",
                        k.sieve_passing.back()));
  }
  if (k.settle) {
    Real g2 = 0;
    for (int d = 0; d < c.dimension; ++d)
      g2 += c.domain.gravity_m_s2[static_cast<std::size_t>(d)] *
            c.domain.gravity_m_s2[static_cast<std::size_t>(d)];
    if (!(g2 > 0))
      error(loc(pt, "settle", pw), kp + ".settle",
            "settling needs gravity: set [domain] gravity_m_s2");
  }
}

// What a dense packing needs (dem/dense_packing.hpp): a box to fill and gravity along one axis
// (the floor it is laid up from).
void Builder::read_dense_packing(const Config& c, const toml::table& pt, const SourceLocation& pw,
                                 const std::string& kp, const PartConfig& p) {
  const SourceLocation mw = loc(pt, "method", pw);
  if (p.region.type != RegionType::Box)
    error(mw, kp + ".method",
          "method = \"dense\" fills a box region; give the part a box (the parts it is carved "
          "around may be of any shape)");
  int axes = 0;
  for (int d = 0; d < c.dimension; ++d)
    axes += c.domain.gravity_m_s2[static_cast<std::size_t>(d)] != 0;
  if (axes != 1)
    error(mw, kp + ".method",
          "method = \"dense\" is laid from the floor up: it needs [domain] gravity_m_s2 along "
          "one axis");
}

// Absorbing walls: faces of their own (not also rigid walls, not twice) and the bed's
// impedance (Hertz contacts have no fixed stiffness: their P-wave speed must be given).
void Builder::read_absorbing_walls(const toml::table& dt, const SourceLocation& dw,
                                   const std::string& key, int dim, const DomainConfig& domain,
                                   DemConfig& d) {
  const std::string ak = key + ".dem.absorbing_walls";
  const auto& arr = *dt.get("absorbing_walls")->as_array();
  d.absorbing_walls = read_faces(arr, dw, ak, dim);
  check_not_symmetry(arr, dw, ak, domain);
  std::vector<std::string> seen;
  for (std::size_t j = 0; j < arr.size(); ++j) {
    const std::string name = arr.get(j)->as_string()->get();
    const SourceLocation fw = where_of(*arr.get(j), dw);
    const bool rigid = std::any_of(d.walls.begin(), d.walls.end(),
                                   [&](Face f) { return name == kFaceNames[static_cast<int>(f)]; });
    if (rigid)
      error(fw, fmt::format("{}[{}]", ak, j),
            fmt::format("\"{}\" is also in walls: a face is either a rigid or an absorbing "
                        "wall",
                        name));
    else if (std::find(seen.begin(), seen.end(), name) != seen.end())
      error(fw, fmt::format("{}[{}]", ak, j), fmt::format("\"{}\" is listed twice", name));
    seen.push_back(name);
  }
  const bool absorbing = !d.absorbing_walls.empty();
  static const char* speed_keys[] = {"absorbing_wall_density_kg_m3",
                                     "absorbing_wall_p_wave_speed_m_s",
                                     "absorbing_wall_s_wave_speed_m_s"};
  Real* into[] = {&d.absorbing_density_kg_m3, &d.absorbing_p_wave_speed_m_s,
                  &d.absorbing_s_wave_speed_m_s};
  for (int k = 0; k < 3; ++k) {
    const auto v = opt_num(dt, speed_keys[k]);
    if (!v) continue;
    if (!absorbing)
      error(loc(dt, speed_keys[k], dw), key + ".dem." + speed_keys[k],
            "only used with absorbing_walls");
    *into[k] = *v;
  }
  if (absorbing && d.contact == DemContact::HertzMindlin && !(d.absorbing_p_wave_speed_m_s > 0))
    error(loc(dt, "absorbing_walls", dw), key + ".dem.absorbing_wall_p_wave_speed_m_s",
          "missing: absorbing walls with Hertz-Mindlin contacts need the bed's P-wave speed "
          "(a Hertzian packing has no fixed stiffness to estimate it from; dry sand near the "
          "surface: about 100-300 m/s)");
}

}  // namespace crater::io::reader
