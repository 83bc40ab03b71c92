#include "io/scenario/load.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>
#include <unistd.h>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "core/file_kind.hpp"
#include "io/scenario/schema.hpp"
#include "io/scenario/size_estimate.hpp"
#include "io/scenario/validate.hpp"
#include "mesh/gmsh.hpp"
#include "mesh/solid_mesh.hpp"

namespace crater::io {
namespace fs = std::filesystem;
namespace {

constexpr std::uintmax_t kMaxScenarioBytes = 4u << 20;  // a scenario is text, not data
constexpr double kMaxEntities = 2e8;                    // refuse absurd resolutions early

std::string fnv1a_hex(const std::string& s) {
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return fmt::format("{:016x}", h);
}

// ---- --set overrides ------------------------------------------------------------------

std::vector<std::string> split_path(const std::string& p) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : p) {
    if (c == '.') {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

void apply_override(toml::table& root, const std::string& arg) {
  const SourceLocation where{"--set " + arg, 0, 0};
  const auto eq = arg.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError(where, "", "expected --set dotted.key=VALUE");
  // Blanks around the '=' are allowed ("key = value", as in a TOML file).
  auto trim = [](std::string s) {
    const auto b = s.find_first_not_of(" \t");
    const auto e = s.find_last_not_of(" \t");
    return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
  };
  const std::string path = trim(arg.substr(0, eq));
  const std::string value = trim(arg.substr(eq + 1));
  const auto parts = split_path(path);
  for (const auto& s : parts)
    if (s.empty()) throw InputError(where, path, "empty segment in the key path");

  // The value in TOML syntax; a bare word is taken as a string (--set parts.0.method=sph).
  const bool bare_word =
      !value.empty() && value != "true" && value != "false" && value != "inf" && value != "nan" &&
      std::all_of(value.begin(), value.end(),
                  [](unsigned char ch) { return std::isalpha(ch) || ch == '_' || ch == '-'; });
  toml::table parsed;
  try {
    const std::string text = bare_word ? "v = \"" + value + "\"" : "v = " + value;
    parsed = toml::parse(std::string_view(text), "--set " + arg);
  } catch (const toml::parse_error& e) {
    throw InputError(where, path, "VALUE is not valid TOML: " + std::string(e.description()));
  }
  // Tables created on the way carry the argument as their source, for error messages.
  auto new_table = [&]() {
    toml::table doc = toml::parse(std::string_view("t = {}"), "--set " + arg);
    return std::move(*doc.get("t")->as_table());
  };

  toml::table* t = &root;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    toml::node* next = t->get(parts[i]);
    if (!next) {
      t->insert(parts[i], new_table());
      next = t->get(parts[i]);
    }
    if (auto* arr = next->as_array()) {
      // Element by index or by its `name` key.
      const std::string& sel = parts[++i];
      toml::node* el = nullptr;
      char* end = nullptr;
      const long idx = std::strtol(sel.c_str(), &end, 10);
      if (end && *end == '\0' && idx >= 0 && static_cast<std::size_t>(idx) < arr->size()) {
        el = arr->get(static_cast<std::size_t>(idx));
      } else {
        for (auto& e : *arr)
          if (auto* et = e.as_table())
            if (auto* n = et->get("name"); n && n->value<std::string>() == sel) el = &e;
      }
      if (!el || !el->is_table())
        throw InputError(where, path,
                         fmt::format("'{}' has no entry '{}' (use an index 0..{} or a name)",
                                     parts[i - 1], sel, arr->size() == 0 ? 0 : arr->size() - 1));
      if (i + 1 >= parts.size())
        throw InputError(where, path, "expected a key after the array entry");
      t = el->as_table();
      continue;
    }
    t = next->as_table();
    if (!t) throw InputError(where, path, "'" + parts[i] + "' is not a table");
  }
  if (parts.back().empty()) throw InputError(where, path, "empty key");
  t->insert_or_assign(parts.back(), std::move(*parsed.get("v")));
}

// ---- typed reading of a validated table -----------------------------------------------

Real num(const toml::table& t, const char* key) {
  const toml::node* n = t.get(key);
  if (auto* f = n->as_floating_point()) return f->get();
  return static_cast<Real>(n->as_integer()->get());
}
std::optional<Real> opt_num(const toml::table& t, const char* key) {
  if (!t.get(key)) return std::nullopt;
  return num(t, key);
}
std::string str(const toml::table& t, const char* key) {
  return t.get(key)->as_string()->get();
}
Vec3 vec3(const toml::table& t, const char* key) {
  Vec3 v{};
  if (const toml::node* n = t.get(key)) {
    const auto& a = *n->as_array();
    for (std::size_t i = 0; i < a.size() && i < 3; ++i) {
      if (auto* f = a.get(i)->as_floating_point())
        v[i] = f->get();
      else
        v[i] = static_cast<Real>(a.get(i)->as_integer()->get());
    }
  }
  return v;
}
const toml::table& table(const toml::table& t, const char* key) {
  return *t.get(key)->as_table();
}

SourceLocation loc(const toml::table& t, const char* key, const SourceLocation& fallback) {
  if (const toml::node* n = t.get(key)) return where_of(*n, fallback);
  return fallback;
}

// ---- geometry cross-checks --------------------------------------------------------------

struct Aabb {
  Vec3 lo{}, hi{};
};

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

// Distance from p to a box (0 inside).
Real distance_to_box(const Vec3& p, const Aabb& b, int dim) {
  Real s = 0;
  for (int d = 0; d < dim; ++d) {
    const Real e = std::max({b.lo[d] - p[d], 0.0, p[d] - b.hi[d]});
    s += e * e;
  }
  return std::sqrt(s);
}

// Distance from p to a region (0 inside or on its boundary).
Real distance_to_region(const Vec3& p, const RegionConfig& r, int dim) {
  if (r.type == RegionType::Box) return distance_to_box(p, bounds(r, dim), dim);
  Real s = 0;
  for (int d = 0; d < dim; ++d)
    s += (p[d] - r.center_m[d]) * (p[d] - r.center_m[d]);
  return std::max(0.0, std::sqrt(s) - r.radius_m);
}

// True when the two regions share a volume of positive measure (touching is allowed).
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

class Builder {
 public:
  Builder(toml::table& root, std::string file) : root_(root), file_(std::move(file)) {}

  Config build() {
    Config c;
    c.file = file_;
    const SourceLocation top{file_, 1, 0};
    const auto& sc = table(root_, "scenario");
    c.name = str(sc, "name");
    c.description = str(sc, "description");
    c.dimension = static_cast<int>(sc.get("dimension")->as_integer()->get());
    c.end_time_s = num(sc, "end_time_s");
    const int dim = c.dimension;

    const auto& tt = table(root_, "time");
    c.time.safety_factor = num(tt, "safety_factor");
    c.time.fixed_dt_s = opt_num(tt, "fixed_dt_s");
    c.time.fixed_dt_where = loc(tt, "fixed_dt_s", top);
    c.time.max_steps = tt.get("max_steps")->as_integer()->get();
    c.time.energy_warn_error = num(tt, "energy_warn_error");
    c.time.energy_stop_error = num(tt, "energy_stop_error");
    if (c.time.energy_stop_error > 0 && c.time.energy_warn_error > c.time.energy_stop_error)
      error(loc(tt, "energy_warn_error", top), "time.energy_warn_error",
            fmt::format("expected at most time.energy_stop_error = {}, got {}",
                        c.time.energy_stop_error, c.time.energy_warn_error));

    const auto& ot = table(root_, "output");
    c.output.interval_s = opt_num(ot, "interval_s").value_or(c.end_time_s / 20);
    c.output.history_every = ot.get("history_every")->as_integer()->get();
    c.output.vtu = ot.get("vtu")->as_boolean()->get();
    c.output.checkpoint_every_steps = ot.get("checkpoint_every_steps")->as_integer()->get();
    c.output.checkpoint_every_s = num(ot, "checkpoint_every_s");
    c.output.checkpoint_keep = ot.get("checkpoint_keep")->as_integer()->get();
    c.output.max_frames = ot.get("max_frames")->as_integer()->get();
    c.output.max_bytes = num(ot, "max_bytes");
    c.output.memory_limit_fraction = num(ot, "memory_limit_fraction");
    c.output.interval_where = loc(ot, "interval_s", top);
    check_frame_count(c);
    c.output.vtu_encoding =
        str(ot, "vtu_encoding") == "base64" ? VtuEncoding::Base64 : VtuEncoding::Appended;
    if (c.output.interval_s > c.end_time_s)
      c.warnings.push_back(fmt::format(
          "output.interval_s = {} s exceeds scenario.end_time_s = {} s: only the first and "
          "last frames are written",
          c.output.interval_s, c.end_time_s));

    const auto& dt = table(root_, "domain");
    c.domain.min_m = vec3(dt, "min_m");
    c.domain.max_m = vec3(dt, "max_m");
    c.domain.gravity_m_s2 = vec3(dt, "gravity_m_s2");
    c.domain.outflow = str(dt, "outflow") == "remove" ? Outflow::Remove : Outflow::Stop;
    for (int d = 0; d < dim; ++d)
      if (!(c.domain.max_m[d] > c.domain.min_m[d])) {
        domain_ok_ = false;
        error(loc(dt, "max_m", top), "domain.max_m",
              fmt::format("expected every component above domain.min_m = {}, got {}",
                          vec_text(c.domain.min_m, dim), vec_text(c.domain.max_m, dim)));
        break;
      }

    read_materials(c, top);
    read_parts(c, top);
    read_contacts(c, top);
    read_probes(c, top);
    if (suppressed_ > 0)
      errors_.emplace_back(
          SourceLocation{file_, 0, 0}, "",
          fmt::format("{} more errors not shown ({} are listed)", suppressed_, kMaxErrors));
    if (!errors_.empty()) throw InputErrors(std::move(errors_));
    for (auto& wmsg : c_warnings_)
      c.warnings.push_back(std::move(wmsg));
    return c;
  }

 private:
  // At most kMaxErrors are kept (20,000 overlapping parts make 2e8 messages otherwise).
  void error(const SourceLocation& w, const std::string& key, const std::string& what) {
    if (errors_.size() >= kMaxErrors) {
      ++suppressed_;
      return;
    }
    errors_.emplace_back(w, key, what);
  }

  // A law's constant problems, each at the line and key of the constant at fault.
  void report(const toml::table& t, const SourceLocation& w, const std::string& key,
              const std::vector<materials::ConstantProblem>& problems) {
    for (const auto& p : problems) {
      if (p.key.empty())
        error(w, key, p.message);
      else
        error(loc(t, p.key.c_str(), w), key + "." + p.key, p.message);
    }
  }

  void read_materials(Config& c, const SourceLocation& top) {
    const auto& arr = *root_.get("materials")->as_array();
    for (std::size_t i = 0; i < arr.size(); ++i) {
      const auto& t = *arr.get(i)->as_table();
      const SourceLocation w = where_of(t, top);
      const std::string key = fmt::format("materials[{}]", i);
      MaterialConfig m;
      m.name = str(t, "name");
      m.model = str(t, "model");
      m.where = w;
      m.rho0_kg_m3 = num(t, "rho0_kg_m3");
      for (const auto& other : c.materials)
        if (other.name == m.name)
          error(loc(t, "name", w), key + ".name",
                fmt::format("duplicate material name '{}' (first at line {})", m.name,
                            other.where.line));
      if (m.model == "jwl") {
        materials::JwlParams p;
        p.rho0_kg_m3 = m.rho0_kg_m3;
        p.a_pa = num(t, "a_pa");
        p.b_pa = num(t, "b_pa");
        p.r1 = num(t, "r1");
        p.r2 = num(t, "r2");
        p.omega = num(t, "omega");
        p.e0_j_m3 = num(t, "e0_j_m3");
        p.d_cj_m_s = num(t, "d_cj_m_s");
        report(t, w, key, materials::jwl_check(p));
        m.eos = p;
      } else if (m.model == "granular") {
        m.granular.shear_modulus_pa = num(t, "shear_modulus_pa");
        m.granular.poisson_ratio = num(t, "poisson_ratio");
        m.granular.friction = num(t, "friction");
        m.granular.restitution = num(t, "restitution");
      } else if (m.model == "elastic" || m.model == "johnson_cook" || m.model == "drucker_prager") {
        read_solid(t, w, key, m);
      } else if (m.model == "ideal_gas") {
        materials::IdealGasParams p;
        p.gamma = num(t, "gamma");
        report(t, w, key, materials::ideal_gas_check(p));
        m.eos = p;
      } else {
        materials::TaitParams p;
        p.rho0_kg_m3 = m.rho0_kg_m3;
        p.c0_m_s = num(t, "c0_m_s");
        p.gamma = num(t, "gamma");
        p.background_pa = num(t, "background_pa");
        report(t, w, key, materials::tait_check(p));
        m.eos = p;
      }
      c.materials.push_back(std::move(m));
    }
  }

  void read_solid(const toml::table& t, const SourceLocation& w, const std::string& key,
                  MaterialConfig& m) {
    const materials::ElasticParams elastic{.youngs_modulus_pa = num(t, "youngs_modulus_pa"),
                                           .poisson_ratio = num(t, "poisson_ratio")};
    if (m.model == "elastic") {
      m.solid.strength = elastic;
    } else if (m.model == "johnson_cook") {
      materials::JohnsonCookParams p;
      p.elastic = elastic;
      p.a_pa = num(t, "a_pa");
      p.b_pa = num(t, "b_pa");
      p.n = num(t, "n");
      p.c = num(t, "c");
      p.m = num(t, "m");
      p.reference_strain_rate_1_s = num(t, "reference_strain_rate_1_s");
      p.thermal_softening = t.get("thermal_softening")->as_boolean()->get();
      p.room_temperature_k = num(t, "room_temperature_k");
      p.melt_temperature_k = num(t, "melt_temperature_k");
      p.specific_heat_j_kg_k = num(t, "specific_heat_j_kg_k");
      p.taylor_quinney = num(t, "taylor_quinney");
      if (!(p.melt_temperature_k > p.room_temperature_k))
        error(
            loc(t, "melt_temperature_k", w), key + ".melt_temperature_k",
            fmt::format("expected a melting temperature above room_temperature_k = {} K, got {} K",
                        p.room_temperature_k, p.melt_temperature_k));
      m.solid.strength = p;
      if (const toml::node* dn = t.get("damage")) {
        const auto& dt = *dn->as_table();
        materials::JohnsonCookDamageParams d;
        d.d1 = num(dt, "d1");
        d.d2 = num(dt, "d2");
        d.d3 = num(dt, "d3");
        d.d4 = num(dt, "d4");
        d.d5 = num(dt, "d5");
        d.reference_strain_rate_1_s = p.reference_strain_rate_1_s;
        d.room_temperature_k = p.room_temperature_k;
        d.melt_temperature_k = p.melt_temperature_k;
        // The failure strain at zero triaxiality must be positive, or every element fails at
        // its first plastic step.
        if (!(d.d1 + d.d2 > 0))
          error(where_of(dt, w), key + ".damage",
                fmt::format("expected D1 + D2 > 0 (the failure strain at zero triaxiality), got "
                            "{}",
                            d.d1 + d.d2));
        m.solid.damage = d;
      }
    } else {
      const Real phi = num(t, "friction_angle_deg") * M_PI / 180;
      const Real psi =
          opt_num(t, "dilation_angle_deg").value_or(num(t, "friction_angle_deg")) * M_PI / 180;
      const std::string fit = str(t, "fit");
      const auto f = fit == "extension"      ? materials::MohrCoulombFit::kExtensionCone
                     : fit == "plane_strain" ? materials::MohrCoulombFit::kPlaneStrain
                                             : materials::MohrCoulombFit::kCompressionCone;
      if (psi > phi + 1e-12)
        error(loc(t, "dilation_angle_deg", w), key + ".dilation_angle_deg",
              "expected a dilation angle at most the friction angle (more dilation than "
              "friction is not admissible)");
      m.solid.strength =
          materials::drucker_prager_from_mohr_coulomb(elastic, num(t, "cohesion_pa"), phi, psi, f);
    }
    report(t, w, key, materials::strength_check(m.solid.strength));
  }

  RegionConfig read_region(const toml::table& t, const SourceLocation& w, const std::string& key,
                           int dim) {
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

  void read_parts(Config& c, const SourceLocation& top) {
    const int dim = c.dimension;
    const auto& arr = *root_.get("parts")->as_array();
    for (std::size_t i = 0; i < arr.size(); ++i) {
      const auto& t = *arr.get(i)->as_table();
      const SourceLocation w = where_of(t, top);
      const std::string key = fmt::format("parts[{}]", i);
      PartConfig p;
      p.where = w;
      p.name = str(t, "name");
      p.method = str(t, "method");
      // An FEM part read from a mesh file takes its geometry from the mesh; every other part
      // is a region filled at a spacing.
      const toml::node* fem_node = t.get("fem");
      const bool from_mesh = p.method == "fem" && fem_node && fem_node->is_table() &&
                             fem_node->as_table()->get("mesh_file");
      if (from_mesh) {
        for (const char* k : {"spacing_m", "region"})
          if (t.get(k))
            error(loc(t, k, w), key + "." + k,
                  "not used with fem.mesh_file (the mesh gives the geometry); remove it");
      } else {
        for (const char* k : {"spacing_m", "region"})
          if (!t.get(k))
            error(w, key + "." + k,
                  std::string("missing required key (") +
                      (k == std::string("region") ? "a table [parts.region]" : "a number, in m") +
                      ")" + (p.method == "fem" ? ", or give fem.mesh_file" : ""));
      }
      p.spacing_m = opt_num(t, "spacing_m").value_or(0);
      for (const auto& other : c.parts)
        if (other.name == p.name)
          error(
              loc(t, "name", w), key + ".name",
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
      if (region_table && p.method == "fem" && p.region.type != RegionType::Box)
        error(loc(*region_table, "type", w), key + ".region.type",
              "an FEM part's structured mesh fills a box; for other shapes give fem.mesh_file");

      const auto& it_init = table(t, "initial");
      p.initial.density_kg_m3 = opt_num(it_init, "density_kg_m3");
      p.initial.pressure_pa = opt_num(it_init, "pressure_pa");
      p.initial.velocity_m_s = vec3(it_init, "velocity_m_s");
      if (const toml::node* zn = t.get("zones")) {
        const auto& za = *zn->as_array();
        for (std::size_t j = 0; j < za.size(); ++j) {
          const auto& zt = *za.get(j)->as_table();
          const SourceLocation zw = where_of(zt, w);
          ZoneConfig z;
          const auto& zr = table(zt, "region");
          z.region =
              read_region(zr, where_of(zr, zw), fmt::format("{}.zones[{}].region", key, j), dim);
          z.spacing_m = opt_num(zt, "spacing_m");
          if (z.spacing_m) check_zone_spacing(zt, zw, fmt::format("{}.zones[{}]", key, j), z, dim);
          z.density_kg_m3 = opt_num(zt, "density_kg_m3");
          z.pressure_pa = opt_num(zt, "pressure_pa");
          if (zt.get("velocity_m_s")) z.velocity_m_s = vec3(zt, "velocity_m_s");
          p.zones.push_back(z);
        }
      }

      if (region_table) check_region(c, t, *region_table, w, key, p);

      // The material must suit the method.
      if (p.material < c.materials.size()) {
        const std::string& model = c.materials[p.material].model;
        const char* needs =
            model == "granular"                                                            ? "dem"
            : (model == "elastic" || model == "johnson_cook" || model == "drucker_prager") ? "fem"
                                                                                           : "sph";
        static const std::map<std::string, std::string> kinds = {
            {"sph", "an equation-of-state material (jwl, ideal_gas, tait)"},
            {"dem", "a \"granular\" material"},
            {"fem", "a solid material (elastic, johnson_cook, drucker_prager)"}};
        if (p.method != needs)
          error(loc(t, "material", w), key + ".material",
                fmt::format("method \"{}\" needs {}; '{}' is \"{}\"", p.method, kinds.at(p.method),
                            c.materials[p.material].name, model));
      }
      if (p.method == "sph") read_sph(c, t, w, key, p);
      if (p.method == "dem") read_dem(c, t, w, key, p);
      if (p.method == "fem") read_fem(c, t, w, key, p);
      c.parts.push_back(std::move(p));
    }

    // Carving: a part may leave the regions of named other parts empty.
    for (std::size_t i = 0; i < arr.size(); ++i) {
      const auto& t = *arr.get(i)->as_table();
      const toml::node* cn = t.get("carve");
      if (!cn || i >= c.parts.size()) continue;
      const SourceLocation cw = loc(t, "carve", where_of(t, top));
      PartConfig& p = c.parts[i];
      if (p.method == "fem")
        error(cw, fmt::format("parts[{}].carve", i),
              "only sph and dem parts are carved; an fem part's mesh is its shape");
      if (p.packing.settle)
        error(cw, fmt::format("parts[{}].carve", i),
              "a carved part cannot be settled yet (the hole would fill while it settles); set "
              "packing.settle = false");
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
    auto carves = [&](std::size_t a, std::size_t b) {
      const auto& k = c.parts[a].carve;
      return std::find(k.begin(), k.end(), b) != k.end();
    };

    // Bodies must not overlap (e.g. the plate "at 0.5 m depth" read as its top face).
    for (std::size_t a = 0; a < c.parts.size(); ++a)
      for (std::size_t b = a + 1; b < c.parts.size(); ++b)
        if (!carves(a, b) && !carves(b, a) && overlap(c.parts[a].region, c.parts[b].region, dim)) {
          if (errors_.size() >= kMaxErrors) {
            ++suppressed_;  // counted, not formatted: thousands of parts give millions
            continue;
          }
          error(c.parts[b].region.where, fmt::format("parts[{}].region", b),
                fmt::format("bodies overlap: part '{}' intersects part '{}' (line {})",
                            c.parts[b].name, c.parts[a].name, c.parts[a].region.where.line));
        }
  }

  // VTU frames: end_time_s / interval_s of them (and the first; at most time.max_steps + 1).
  // More than output.max_frames is a mistake in the interval (1e-15 s wrote a frame every
  // step), not a wish.
  void check_frame_count(const Config& c) {
    if (!c.output.vtu || !(c.output.interval_s > 0) || !(c.end_time_s > 0)) return;
    // A step ends on at most one frame: time.max_steps bounds the count as well.
    Real frames = std::ceil(c.end_time_s / c.output.interval_s) + 1;
    if (c.time.max_steps > 0) frames = std::min(frames, static_cast<Real>(c.time.max_steps) + 1);
    if (frames > static_cast<Real>(c.output.max_frames))
      error(c.output.interval_where, "output.interval_s",
            fmt::format("expected at most output.max_frames = {} VTU frames over "
                        "scenario.end_time_s = {} s (an interval of at least {:.4g} s); "
                        "interval_s = {} s gives {:.4g} frames (raise output.max_frames if "
                        "that many are wanted)",
                        c.output.max_frames, c.end_time_s,
                        c.end_time_s / static_cast<Real>(c.output.max_frames - 1),
                        c.output.interval_s, frames));
  }

  // A zone's own lattice: at least two sites across, and not an absurd count.
  void check_zone_spacing(const toml::table& zt, const SourceLocation& zw, const std::string& key,
                          const ZoneConfig& z, int dim) {
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
  void check_region(const Config& c, const toml::table& t, const toml::table& rt,
                    const SourceLocation& w, const std::string& key, PartConfig& p) {
    const int dim = c.dimension;
    {
      // Inside the domain (when both are well formed: one error per mistake).
      const Aabb b = bounds(p.region, dim);
      bool well_formed = domain_ok_;
      for (int d = 0; d < dim; ++d)
        well_formed = well_formed && b.hi[d] > b.lo[d];
      for (int d = 0; d < dim && well_formed; ++d)
        if (b.lo[d] < c.domain.min_m[d] || b.hi[d] > c.domain.max_m[d]) {
          error(where_of(rt, w), key + ".region",
                fmt::format("expected the region inside the domain {} .. {}; it spans {} .. {}",
                            vec_text(c.domain.min_m, dim), vec_text(c.domain.max_m, dim),
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
      } else if (p.method == "fem" ? p.spacing_m > min_extent * (1 + 1e-9)
                                   : p.spacing_m > min_extent / 2)
        error(loc(t, "spacing_m", w), key + ".spacing_m",
              p.method == "fem"
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

  void read_probes(Config& c, const SourceLocation& top) {
    const toml::node* pn = root_.get("probes");
    if (!pn) return;
    const auto& t = *pn->as_table();
    const SourceLocation w = where_of(t, top);
    c.probes.stress_time_s = num(t, "stress_time_s");
    c.probes.surface_bin_m = opt_num(t, "surface_bin_m");
    auto part = [&](const char* key, const char* method) -> std::optional<std::size_t> {
      const toml::node* n = t.get(key);
      if (!n) return std::nullopt;
      const std::string name = n->as_string()->get();
      const auto it = std::find_if(c.parts.begin(), c.parts.end(),
                                   [&](const PartConfig& p) { return p.name == name; });
      if (it == c.parts.end() || it->method != method) {
        std::string known;
        for (const auto& p : c.parts)
          if (p.method == method) known += (known.empty() ? "'" : ", '") + p.name + "'";
        error(loc(t, key, w), std::string("probes.") + key,
              fmt::format("expected the name of a {} part ({}), got '{}'", method,
                          known.empty() ? std::string("the scenario has none") : known, name));
        return std::nullopt;
      }
      return static_cast<std::size_t>(it - c.parts.begin());
    };
    c.probes.plate = part("plate", "fem");
    c.probes.soil = part("soil", "dem");
    if (c.probes.plate && c.probes.stress_time_s > c.end_time_s)
      c_warnings_.push_back(
          fmt::format("probes.stress_time_s = {} s is after scenario.end_time_s = {} s: "
                      "plate_peak_von_mises_pa will not be measured",
                      c.probes.stress_time_s, c.end_time_s));
  }

  void read_contacts(Config& c, const SourceLocation& top) {
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
      std::array<std::string, 2> methods;
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
        methods[j] = it->method;
      }
      if (!ok) continue;
      // Particles against a solid's surface, or SPH against DEM particles.
      std::array<std::string, 2> m = methods;
      std::sort(m.begin(), m.end());
      const bool supported = (m[0] == "dem" && (m[1] == "fem" || m[1] == "sph")) ||
                             (m[0] == "fem" && (m[1] == "sph" || m[1] == "fem"));
      if (!supported)
        error(pw, key + ".parts",
              fmt::format("contacts join sph or dem particles to an fem surface, sph to dem "
                          "particles, or two fem surfaces; '{}' and '{}' are {} and {}",
                          c.parts[k.parts[0]].name, c.parts[k.parts[1]].name, methods[0],
                          methods[1]));
      for (const auto& other : c.contacts)
        if (std::minmax(other.parts[0], other.parts[1]) == std::minmax(k.parts[0], k.parts[1]))
          error(pw, key + ".parts",
                fmt::format("a second contact between '{}' and '{}' (first at line {})",
                            c.parts[k.parts[0]].name, c.parts[k.parts[1]].name, other.where.line));
      c.contacts.push_back(k);
    }
  }

  std::vector<Face> read_faces(const toml::array& walls, const SourceLocation& w,
                               const std::string& key, int dim) {
    static const char* names[] = {"left", "right", "bottom", "top", "back", "front"};
    std::vector<Face> faces;
    for (std::size_t j = 0; j < walls.size(); ++j) {
      const std::string face = walls.get(j)->as_string()->get();
      const int f =
          static_cast<int>(std::find(std::begin(names), std::end(names), face) - std::begin(names));
      if (f / 2 >= dim) {
        error(where_of(*walls.get(j), w), fmt::format("{}[{}]", key, j),
              fmt::format("\"{}\" is a face of the z axis; the scenario is 2D", face));
        continue;
      }
      faces.push_back(static_cast<Face>(f));
    }
    return faces;
  }

  void read_fem(const Config& c, const toml::table& t, const SourceLocation& w,
                const std::string& key, PartConfig& p) {
    const int dim = c.dimension;
    const auto& ft = table(t, "fem");
    const SourceLocation fw = where_of(ft, w);
    FemConfig& f = p.fem;
    f.hourglass_stiffness = str(ft, "hourglass") == "stiffness";
    f.hourglass_coefficient = num(ft, "hourglass_coefficient");
    f.bulk_viscosity_quadratic = num(ft, "bulk_viscosity_quadratic");
    f.bulk_viscosity_linear = num(ft, "bulk_viscosity_linear");
    f.initial_temperature_k = num(ft, "initial_temperature_k");
    f.erosion_plastic_strain = opt_num(ft, "erosion_plastic_strain");
    f.erode_inverted = ft.get("erode_inverted")->as_boolean()->get();
    f.erosion_step_ratio = num(ft, "erosion_step_ratio");
    // A solid starts unstressed at its reference density; only velocities can be set.
    const auto& it_init = table(t, "initial");
    for (const char* k : {"density_kg_m3", "pressure_pa"})
      if (it_init.get(k))
        error(loc(it_init, k, w), key + ".initial." + k,
              "not used by fem parts (a solid starts unstressed at the material's rho0_kg_m3)");
    if (const toml::node* zn = t.get("zones"))
      for (std::size_t j = 0; j < zn->as_array()->size(); ++j) {
        const auto& zt = *zn->as_array()->get(j)->as_table();
        for (const char* k : {"spacing_m", "density_kg_m3", "pressure_pa"})
          if (zt.get(k))
            error(loc(zt, k, w), fmt::format("{}.zones[{}].{}", key, j, k),
                  "not used by fem parts (zones set the initial velocity of the nodes in them)");
      }
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
          c_warnings_.push_back(fmt::format(
              "part '{}': the region's extent along axis {} ({} m) is not a multiple of "
              "spacing_m = {} m; the elements are stretched to {} whole ones",
              p.name, d, p.region.max_m[d] - p.region.min_m[d], p.spacing_m,
              std::max<Real>(1, std::round(cells))));
      }
    }
    if (const toml::node* bn = ft.get("boundary")) {
      static const char* faces[] = {"left", "right", "bottom", "top", "back", "front"};
      const auto& ba = *bn->as_array();
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
          const int fi = static_cast<int>(std::find(std::begin(faces), std::end(faces), face) -
                                          std::begin(faces));
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
                error(where_of(e, bw), bk + ".components",
                      "\"z\" is not a component of a 2D scenario");
              else
                b.components[static_cast<std::size_t>(a)] = true;
            }
          }
        }
        f.boundaries.push_back(b);
      }
    }
    if (!f.mesh_file.empty()) read_fem_mesh(c, ft, fw, key, p);
    if (const toml::node* ln = ft.get("loads")) read_fem_loads(*ln->as_array(), fw, key, dim, p);
  }

  // [[parts.fem.loads]]: a face of the part's box, an optional box on it, a pressure table.
  void read_fem_loads(const toml::array& la, const SourceLocation& fw, const std::string& key,
                      int dim, PartConfig& p) {
    static const char* faces[] = {"left", "right", "bottom", "top", "back", "front"};
    for (std::size_t j = 0; j < la.size(); ++j) {
      const auto& lt = *la.get(j)->as_table();
      const SourceLocation lw = where_of(lt, fw);
      const std::string lk = fmt::format("{}.fem.loads[{}]", key, j);
      FemLoadConfig l;
      l.where = lw;
      l.type = FemLoadType::Pressure;
      const std::string face = str(lt, "face");
      const int fi =
          static_cast<int>(std::find(std::begin(faces), std::end(faces), face) - std::begin(faces));
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
              error(
                  loc(rt, "min_m", rw), lk + ".region",
                  fmt::format("the box ({} .. {}) does not meet the part's {} face, which spans "
                              "{} .. {}",
                              vec_text(l.region->min_m, dim), vec_text(l.region->max_m, dim), face,
                              vec_text(p.region.min_m, dim), vec_text(p.region.max_m, dim)));
          }
      }
      auto reals = [&](const char* name) {
        std::vector<Real> v;
        if (const toml::node* n = lt.get(name))
          for (const auto& e : *n->as_array())
            v.push_back(e.value<double>().value_or(0.0));
        return v;
      };
      l.time_s = reals("time_s");
      l.pressure_pa = reals("pressure_pa");
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
      if (ok) p.fem.loads.push_back(l);
    }
  }

  // Mesh files are read when the scenario is, so that a malformed mesh is an input error
  // (exit 2) before anything runs; the part is built from the elements taken from it here
  // (a degenerate element is found then: still an input error, at `crater check` too).
  void read_fem_mesh(const Config& c, const toml::table& ft, const SourceLocation& fw,
                     const std::string& key, PartConfig& p) {
    FemConfig& f = p.fem;
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
      f.elements = std::make_shared<const mesh::SolidElements>(mesh::solid_elements(
          mesh::read_gmsh(f.mesh_file), f.mesh_file, f.mesh_group, c.dimension));
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
              fmt::format("no physical group '{}' with nodes of the part in {} (groups: {})",
                          b.group, f.mesh_file, known.empty() ? "none" : known));
      }
    } catch (const InputError& e) {
      // The reader names the file and line of the mesh; the key is the scenario's (the group
      // when the part names one and the reader found none of its elements).
      if (!e.key().empty())
        errors_.push_back(e);
      else if (!f.mesh_group.empty() &&
               std::string(e.what()).find("in group '") != std::string::npos)
        error(loc(ft, "mesh_group", fw), key + ".fem.mesh_group", e.what());
      else
        error(e.where(), key + ".fem.mesh_file", e.what());
    }
  }

  // Absorbing walls: faces of their own (not also rigid walls, not twice) and the bed's
  // impedance (Hertz contacts have no fixed stiffness: their P-wave speed must be given).
  void read_absorbing_walls(const toml::table& dt, const SourceLocation& dw, const std::string& key,
                            int dim, DemConfig& d) {
    const std::string ak = key + ".dem.absorbing_walls";
    const auto& arr = *dt.get("absorbing_walls")->as_array();
    d.absorbing_walls = read_faces(arr, dw, ak, dim);
    static const char* names[] = {"left", "right", "bottom", "top", "back", "front"};
    std::vector<std::string> seen;
    for (std::size_t j = 0; j < arr.size(); ++j) {
      const std::string name = arr.get(j)->as_string()->get();
      const SourceLocation fw = where_of(*arr.get(j), dw);
      const bool rigid = std::any_of(d.walls.begin(), d.walls.end(),
                                     [&](Face f) { return name == names[static_cast<int>(f)]; });
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

  void read_dem(const Config& c, const toml::table& t, const SourceLocation& w,
                const std::string& key, PartConfig& p) {
    const int dim = c.dimension;
    const auto& dt = table(t, "dem");
    const SourceLocation dw = where_of(dt, w);
    read_packing(c, t, w, key, p);
    p.dem.radius_max_m = opt_num(dt, "radius_max_m").value_or(0.5 * p.spacing_m);
    p.dem.radius_min_m = opt_num(dt, "radius_min_m").value_or(p.dem.radius_max_m);
    if (!p.packing.random && p.dem.radius_max_m > 0.5 * p.spacing_m * (1 + 1e-12))
      error(loc(dt, "radius_max_m", dw), key + ".dem.radius_max_m",
            fmt::format("expected at most spacing_m / 2 = {} m (grains sit on a lattice of "
                        "pitch spacing_m), got {} m",
                        0.5 * p.spacing_m, p.dem.radius_max_m));
    if (p.dem.radius_min_m > p.dem.radius_max_m)
      error(loc(dt, "radius_min_m", dw), key + ".dem.radius_min_m",
            fmt::format("expected at most radius_max_m = {} m, got {} m", p.dem.radius_max_m,
                        p.dem.radius_min_m));
    p.dem.seed = static_cast<std::uint64_t>(dt.get("seed")->as_integer()->get());
    p.dem.local_damping = num(dt, "local_damping");
    p.dem.rayleigh_fraction = num(dt, "rayleigh_fraction");
    p.dem.walls = read_faces(*dt.get("walls")->as_array(), dw, key + ".dem.walls", dim);
    p.dem.wall_friction = num(dt, "wall_friction");
    p.dem.wall_restitution = num(dt, "wall_restitution");
    p.dem.contact =
        str(dt, "contact") == "linear_spring" ? DemContact::LinearSpring : DemContact::HertzMindlin;
    p.dem.stiffness_step_fraction = num(dt, "stiffness_step_fraction");
    p.dem.hertz_row_of_spheres = str(dt, "hertz_2d") == "row_of_spheres";
    if (p.dem.contact == DemContact::LinearSpring) {
      if (const auto kn = opt_num(dt, "normal_stiffness_n_m")) {
        p.dem.normal_stiffness_n_m = *kn;
        // Mindlin's ratio of tangential to normal stiffness of equal grains.
        const Real nu = p.material < c.materials.size()
                            ? c.materials[p.material].granular.poisson_ratio
                            : Real(0);
        p.dem.shear_stiffness_n_m =
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
    p.dem.rolling_friction = num(dt, "rolling_friction");
    p.dem.rolling_damping = num(dt, "rolling_damping");
    p.dem.rate_dependent_friction = dt.get("rate_dependent_friction")->as_boolean()->get();
    p.dem.friction_rate_beta = num(dt, "friction_rate_beta");
    p.dem.friction_reference_strain_rate = num(dt, "friction_reference_strain_rate");
    read_absorbing_walls(dt, dw, key, dim, p.dem);
    {
      const auto& bt = table(dt, "bonds");
      const SourceLocation bw = where_of(bt, dw);
      DemBondConfig& b = p.dem.bonds;
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
        b.shear_stiffness_pa_m =
            opt_num(bt, "shear_stiffness_pa_m").value_or(b.normal_stiffness_pa_m);
      }
    }
    if (const toml::node* pn = t.get("particles")) {
      const auto& pa = *pn->as_array();
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
        p.dem.particles.push_back(q);
      }
    }
  }

  void read_packing(const Config& c, const toml::table& t, const SourceLocation& w,
                    const std::string& key, PartConfig& p) {
    const auto& pt = table(t, "packing");
    const SourceLocation pw = where_of(pt, w);
    PackingConfig& k = p.packing;
    k.random = str(pt, "method") == "random";
    k.settle = pt.get("settle")->as_boolean()->get();
    k.settle_kinetic_ratio = num(pt, "settle_kinetic_ratio");
    k.settle_max_time_s = num(pt, "settle_max_time_s");
    k.settle_damping = num(pt, "settle_damping");
    k.agitation_m_s = num(pt, "agitation_m_s");
    fs::path cache = str(pt, "cache_dir");
    if (cache.is_relative()) cache = fs::path(file_).parent_path() / cache;
    k.cache_dir = cache.lexically_normal().string();
    const std::string kp = key + ".packing";
    if (k.random) {
      if (!pt.get("porosity"))
        error(pw, kp + ".porosity", "missing: method = \"random\" needs a target porosity");
      else
        k.porosity = num(pt, "porosity");
      if (t.get("particles"))
        error(loc(t, "particles", w), key + ".particles",
              "grains placed by hand cannot also be packed at random; remove one of "
              "[[" +
                  key + ".particles]] and [" + kp + "] method = \"random\"");
    }
    auto reals = [&](const char* name) {
      std::vector<Real> v;
      if (const toml::node* n = pt.get(name))
        for (const auto& e : *n->as_array())
          v.push_back(e.value<double>().value_or(0.0));
      return v;
    };
    k.sieve_diameter_m = reals("sieve_diameter_m");
    k.sieve_passing = reals("sieve_passing");
    if (!k.sieve_diameter_m.empty() || !k.sieve_passing.empty()) {
      const SourceLocation sw = loc(pt, "sieve_diameter_m", pw);
      if (!k.random)
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

  void read_sph(const Config& c, const toml::table& t, const SourceLocation& w,
                const std::string& key, PartConfig& p) {
    const int dim = c.dimension;
    const auto& st = table(t, "sph");
    p.sph.kernel = str(st, "kernel") == "cubic_spline" ? sph::KernelKind::CubicSpline
                                                       : sph::KernelKind::WendlandC2;
    p.sph.h_factor = num(st, "h_factor");
    p.sph.av_alpha = num(st, "av_alpha");
    p.sph.av_beta = num(st, "av_beta");
    p.sph.cfl = num(st, "cfl");
    p.sph.variable_h = st.get("variable_h")->as_boolean()->get();
    p.sph.xsph_epsilon = num(st, "xsph_epsilon");
    p.sph.tensile_epsilon = num(st, "tensile_epsilon");
    p.sph.viscosity_pa_s = num(st, "viscosity_pa_s");
    p.sph.wall_layers = static_cast<int>(st.get("wall_layers")->as_integer()->get());
    p.sph.wall_no_slip = str(st, "wall_slip") == "no";
    const auto& walls = *st.get("walls")->as_array();
    for (std::size_t j = 0; j < walls.size(); ++j) {
      static const char* names[] = {"left", "right", "bottom", "top", "back", "front"};
      const std::string face = walls.get(j)->as_string()->get();
      const int f =
          static_cast<int>(std::find(std::begin(names), std::end(names), face) - std::begin(names));
      if (f / 2 >= dim) {
        error(where_of(*walls.get(j), w), fmt::format("{}.sph.walls[{}]", key, j),
              fmt::format("\"{}\" is a face of the z axis; the scenario is 2D", face));
        continue;
      }
      p.sph.walls.push_back(static_cast<Face>(f));
      // The wall lattice is laid at the part's spacing along the face: the domain's extent
      // along the face's other axes should be a multiple of it, or gaps open at the far end.
      for (int d = 0; d < dim; ++d) {
        if (d == f / 2) continue;
        const Real n = (c.domain.max_m[d] - c.domain.min_m[d]) / p.spacing_m;
        if (std::abs(n - std::round(n)) > 1e-6 * n)
          c_warnings_.push_back(
              fmt::format("part '{}': the domain extent along axis {} ({} m) is not a multiple of "
                          "spacing_m = {} m; the {} wall's particles leave a gap at the far end",
                          p.name, d, c.domain.max_m[d] - c.domain.min_m[d], p.spacing_m, face));
      }
    }
    if (p.sph.wall_no_slip && !p.sph.walls.empty() && p.spacing_m > 0) {
      // Dummy particles fill every walled face over the whole domain, as deep as the kernel
      // support of the largest particle (the coarsest lattice: part or zone).
      Real coarsest = p.spacing_m;
      for (const auto& z : p.zones)
        if (z.spacing_m) coarsest = std::max(coarsest, *z.spacing_m);
      const Real layers =
          std::max<Real>(p.sph.wall_layers, std::ceil(2 * p.sph.h_factor * coarsest / p.spacing_m));
      Real count = 0;
      for (Face f : p.sph.walls) {
        Real n = layers;
        for (int d = 0; d < dim; ++d)
          if (d != static_cast<int>(f) / 2)
            n *= std::max<Real>(1,
                                (c.domain.max_m[d] - c.domain.min_m[d]) / p.spacing_m + 2 * layers);
        count += n;
      }
      p.estimated_wall_count = count;
      if (count > kMaxEntities)
        error(
            loc(st, "walls", w), key + ".sph.walls",
            fmt::format("no-slip walls along the whole domain need about {:.3g} wall particles at "
                        "spacing_m = {} m, above the limit of {:.0e}: shrink [domain] to the "
                        "fluid's reach or coarsen the spacing",
                        count, p.spacing_m, kMaxEntities));
    }
    if (const toml::node* dn = t.get("detonation")) {
      const auto& da = *dn->as_array();
      const bool jwl = p.material < c.materials.size() && c.materials[p.material].model == "jwl";
      for (std::size_t j = 0; j < da.size(); ++j) {
        const auto& dtab = *da.get(j)->as_table();
        DetonationPoint dp;
        dp.point_m = vec3(dtab, "point_m");
        dp.time_s = num(dtab, "time_s");
        const SourceLocation dw = where_of(dtab, w);
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
        if (in_domain && size > 0 && outside > 1e-6 * size)
          error(
              loc(dtab, "point_m", dw), fmt::format("{}.detonation[{}].point_m", key, j),
              fmt::format("expected a point inside the charge's region (part '{}': {}; its "
                          "boundary included); it is at {}, {:.3g} m outside",
                          p.name, region_text(p.region, dim), vec_text(dp.point_m, dim), outside));
        p.detonations.push_back(dp);
      }
    }
  }

  toml::table& root_;
  std::string file_;
  static constexpr std::size_t kMaxErrors = 100;
  std::vector<InputError> errors_;
  std::size_t suppressed_ = 0;
  bool domain_ok_ = true;
  std::vector<std::string> c_warnings_;
};

// Resolution levels: `[levels.<name>]` tables, each a list of overrides (`set`, in --set
// syntax) and a description. They are taken out of the table before validation; the chosen
// level's overrides apply before the command line's.
struct Level {
  std::string name, description;
  std::vector<std::pair<std::string, SourceLocation>> sets;
  std::uint32_t line = 0;
};

std::vector<Level> take_levels(toml::table& root, const std::string& file) {
  std::vector<Level> levels;
  toml::node* ln = root.get("levels");
  if (!ln) return levels;
  const SourceLocation top{file, 1, 0};
  const auto* lt = ln->as_table();
  if (!lt) throw InputError(where_of(*ln, top), "levels", "expected a table of [levels.<name>]");
  for (const auto& [k, v] : *lt) {
    const std::string key = "levels." + std::string(k.str());
    const auto* t = v.as_table();
    if (!t)
      throw InputError(where_of(v, top), key, "expected a table with `set` and `description`");
    Level l;
    l.name = std::string(k.str());
    for (const auto& [kk, vv] : *t) {
      const std::string sub = key + "." + std::string(kk.str());
      if (kk.str() == "description") {
        if (!vv.is_string()) throw InputError(where_of(vv, top), sub, "expected a string");
        l.description = vv.as_string()->get();
      } else if (kk.str() == "set") {
        const auto* arr = vv.as_array();
        if (!arr) throw InputError(where_of(vv, top), sub, "expected an array of \"key=VALUE\"");
        for (std::size_t i = 0; i < arr->size(); ++i) {
          const toml::node& e = *arr->get(i);
          if (!e.is_string())
            throw InputError(where_of(e, top), fmt::format("{}[{}]", sub, i),
                             "expected a string \"dotted.key=VALUE\" (--set syntax)");
          l.sets.emplace_back(e.as_string()->get(), where_of(e, top));
        }
      } else {
        throw InputError(where_of(vv, top), sub, "unknown key (a level has `set`, `description`)");
      }
    }
    l.line = v.source().begin.line;
    levels.push_back(std::move(l));
  }
  // In the file's order (a TOML table's keys come sorted).
  std::stable_sort(levels.begin(), levels.end(),
                   [](const Level& a, const Level& b) { return a.line < b.line; });
  root.erase("levels");
  return levels;
}

Config load_table(toml::table root, const std::string& file,
                  const std::vector<std::string>& overrides, const std::string& level) {
  const std::vector<Level> levels = take_levels(root, file);
  std::string known;
  for (const auto& l : levels)
    known += (known.empty() ? "" : ", ") + l.name;
  if (!level.empty()) {
    const auto it =
        std::find_if(levels.begin(), levels.end(), [&](const Level& l) { return l.name == level; });
    if (it == levels.end())
      throw InputError({"--level " + level, 0, 0}, "",
                       levels.empty()
                           ? fmt::format("the scenario {} defines no levels", file)
                           : fmt::format("no level '{}' in {} (levels: {})", level, file, known));
    for (const auto& [set, where] : it->sets) {
      try {
        apply_override(root, set);
      } catch (const InputError& e) {
        throw InputError(where, fmt::format("levels.{}.set", level), e.what());
      }
    }
  }
  for (const auto& o : overrides)
    apply_override(root, o);

  // The dimension is needed first: it sets the length of every vector key.
  int dim = 2;
  if (auto* sc = root.get("scenario"); sc && sc->is_table())
    if (auto* d = sc->as_table()->get("dimension"); d && d->is_integer()) {
      const auto v = d->as_integer()->get();
      if (v == 2 || v == 3) dim = static_cast<int>(v);
    }

  std::vector<InputError> errors;
  validate_table(root, scenario_schema(), "", dim, SourceLocation{file, 1, 0}, errors);
  if (!errors.empty()) throw InputErrors(std::move(errors));

  Config c = Builder(root, file).build();
  estimate_part_sizes(root, c);
  c.level = level;
  for (const auto& l : levels)
    c.levels.push_back({l.name, l.description});
  std::ostringstream os;
  os << root;
  c.effective_toml = os.str();
  c.hash = fnv1a_hex(c.effective_toml);
  return c;
}

toml::table parse_text(const std::string& text, const std::string& source_name) {
  try {
    return toml::parse(std::string_view(text), source_name);
  } catch (const toml::parse_error& e) {
    const auto& s = e.source();
    SourceLocation w{source_name, static_cast<int>(s.begin.line), static_cast<int>(s.begin.column)};
    throw InputError(w, "", "TOML syntax error: " + std::string(e.description()));
  }
}

}  // namespace

fs::path bundled_scenario_dir() {
  // Installed layout: <prefix>/bin/crater and <prefix>/share/crater/scenarios.
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path().parent_path() / "share/crater/scenarios";
    if (fs::is_directory(installed, ec)) return installed;
  }
  return fs::path(CRATER_SCENARIO_DIR);
}

std::vector<std::string> bundled_scenarios() {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(bundled_scenario_dir(), ec))
    if (e.path().extension() == ".toml") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

fs::path resolve_scenario(const std::string& path_or_name) {
  std::error_code ec;
  const fs::path p(path_or_name);
  if (fs::exists(p, ec)) {
    const std::string kind = not_a_regular_file(p);
    if (!kind.empty())
      throw InputError({path_or_name, 0, 0}, "",
                       "expected a scenario file (TOML text); '" + path_or_name + "' " + kind);
    return p;
  }
  if (path_or_name.find('/') == std::string::npos) {
    const fs::path bundled = bundled_scenario_dir() / (path_or_name + ".toml");
    if (fs::exists(bundled, ec)) return bundled;
  }
  std::string known;
  for (const auto& n : bundled_scenarios())
    known += (known.empty() ? "" : ", ") + n;
  throw InputError({path_or_name, 0, 0}, "",
                   "no such file, and no bundled scenario of that name (bundled: " + known + ")");
}

Config load_scenario(const std::string& path_or_name, const std::vector<std::string>& overrides,
                     const std::string& level) {
  const fs::path path = resolve_scenario(path_or_name);
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  if (ec) throw InputError({path.string(), 0, 0}, "", "cannot read the file: " + ec.message());
  if (size > kMaxScenarioBytes)
    throw InputError({path.string(), 0, 0}, "",
                     fmt::format("file is {} bytes; a scenario file is at most {} bytes", size,
                                 kMaxScenarioBytes));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError({path.string(), 0, 0}, "", "cannot open the file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return load_scenario_text(ss.str(), path.string(), overrides, level);
}

Config load_scenario_text(const std::string& text, const std::string& source_name,
                          const std::vector<std::string>& overrides, const std::string& level) {
  if (text.find('\0') != std::string::npos)
    throw InputError({source_name, 0, 0}, "", "expected a text (TOML) file, found a NUL byte");
  return load_table(parse_text(text, source_name), source_name, overrides, level);
}

}  // namespace crater::io
