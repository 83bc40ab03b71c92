// The scenario reader's internals, shared by load.cpp and the read_*.cpp files (one file per
// section of the scenario): typed access to a validated table, the error list, the region
// geometry of the cross-checks, and the Builder that turns the validated table into a Config.
// Only io/scenario includes this header.
#pragma once

#include <toml++/toml.h>
#include <algorithm>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include "io/scenario/config.hpp"
#include "io/scenario/validate.hpp"
#include "materials/eos/constant_problem.hpp"

namespace crater::io::reader {

inline constexpr double kMaxEntities = 2e8;  // refuse absurd resolutions early

// ---- typed reading of a validated table (the schema has checked type and presence) ------

inline Real num(const toml::table& t, const char* key) {
  const toml::node* n = t.get(key);
  if (auto* f = n->as_floating_point()) return f->get();
  return static_cast<Real>(n->as_integer()->get());
}
inline std::optional<Real> opt_num(const toml::table& t, const char* key) {
  if (!t.get(key)) return std::nullopt;
  return num(t, key);
}
inline std::string str(const toml::table& t, const char* key) {
  return t.get(key)->as_string()->get();
}
inline Vec3 vec3(const toml::table& t, const char* key) {
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
/// An array of numbers; empty when the key is absent.
inline std::vector<Real> reals(const toml::table& t, const char* key) {
  std::vector<Real> v;
  if (const toml::node* n = t.get(key))
    for (const auto& e : *n->as_array())
      v.push_back(e.value<double>().value_or(0.0));
  return v;
}
inline const toml::table& table(const toml::table& t, const char* key) {
  return *t.get(key)->as_table();
}
/// Where `key` of `t` is, else `fallback`.
inline SourceLocation loc(const toml::table& t, const char* key, const SourceLocation& fallback) {
  if (const toml::node* n = t.get(key)) return where_of(*n, fallback);
  return fallback;
}

/// The faces of the domain or of a part's box by their scenario names, in parts::Face order.
inline constexpr const char* kFaceNames[] = {"left", "right", "bottom", "top", "back", "front"};
/// Index of a face name in kFaceNames (6 when it is none).
inline int face_index(const std::string& name) {
  return static_cast<int>(std::find(std::begin(kFaceNames), std::end(kFaceNames), name) -
                          std::begin(kFaceNames));
}

// ---- errors -------------------------------------------------------------------------------

/// The errors found in one file. At most kMax are kept (20,000 overlapping parts make 2e8
/// messages otherwise); the rest are counted.
class ErrorList {
 public:
  static constexpr std::size_t kMax = 100;
  void add(const SourceLocation& w, const std::string& key, const std::string& what) {
    if (errors_.size() >= kMax) {
      ++suppressed_;
      return;
    }
    errors_.emplace_back(w, key, what);
  }
  /// An error as it was thrown (a mesh file's line), kept whatever the count.
  void add(const InputError& e) { errors_.push_back(e); }
  bool full() const { return errors_.size() >= kMax; }
  /// One more error counted, not formatted.
  void suppress() { ++suppressed_; }
  /// Throws InputErrors when there is any (with a line for those not shown).
  void throw_if_any(const std::string& file);

 private:
  std::vector<InputError> errors_;
  std::size_t suppressed_ = 0;
};

/// A law's constant problems, each at the line and key of the constant at fault.
void report(ErrorList& errors, const toml::table& t, const SourceLocation& w,
            const std::string& key, const std::vector<materials::ConstantProblem>& problems);

// ---- region geometry of the cross-checks (read_parts.cpp) ---------------------------------

struct Aabb {
  Vec3 lo{}, hi{};
};

Aabb bounds(const RegionConfig& r, int dim);
Real volume(const RegionConfig& r, int dim);
/// Distance from p to a region (0 inside or on its boundary).
Real distance_to_region(const Vec3& p, const RegionConfig& r, int dim);
/// True when the two regions share a volume of positive measure (touching is allowed).
bool overlap(const RegionConfig& a, const RegionConfig& b, int dim);
std::string vec_text(const Vec3& v, int dim);
std::string region_text(const RegionConfig& r, int dim);

// ---- the builder ---------------------------------------------------------------------------

/// Builds the Config from the validated table, cross-checking what the schema cannot (names,
/// geometry, combinations of keys); every problem is collected, then thrown together.
class Builder {
 public:
  Builder(toml::table& root, std::string file) : root_(root), file_(std::move(file)) {}

  Config build();

 private:
  void error(const SourceLocation& w, const std::string& key, const std::string& what) {
    errors_.add(w, key, what);
  }

  // load.cpp: [scenario], [time], [output], [domain]
  void read_top(Config& c, const SourceLocation& top);
  void check_frame_count(const Config& c);

  // read_materials.cpp
  void read_materials(Config& c, const SourceLocation& top);

  // read_parts.cpp: the keys every part has, its region and zones, carving, overlaps
  void read_parts(Config& c, const SourceLocation& top);
  PartConfig read_part(const Config& c, const toml::table& t, const SourceLocation& w,
                       const std::string& key);
  // Zones of a part that takes only their velocity (dem, fem): their other keys are errors.
  void zones_velocity_only(const toml::table& t, const SourceLocation& w, const std::string& key,
                           const char* why);
  void read_zones(const toml::array& za, const SourceLocation& w, const std::string& key, int dim,
                  PartConfig& p);
  void check_method_material(const Config& c, const toml::table& t, const SourceLocation& w,
                             const std::string& key, const PartConfig& p);
  void read_carving(Config& c, const toml::array& arr, const SourceLocation& top);
  void check_overlaps(const Config& c);
  RegionConfig read_region(const toml::table& t, const SourceLocation& w, const std::string& key,
                           int dim);
  void check_zone_spacing(const toml::table& zt, const SourceLocation& zw, const std::string& key,
                          const ZoneConfig& z, int dim);
  void check_region(const Config& c, const toml::table& t, const toml::table& rt,
                    const SourceLocation& w, const std::string& key, PartConfig& p);
  std::vector<Face> read_faces(const toml::array& walls, const SourceLocation& w,
                               const std::string& key, int dim);
  void check_not_symmetry(const toml::array& walls, const SourceLocation& w, const std::string& key,
                          const DomainConfig& domain);

  // read_sph.cpp
  void read_sph(const Config& c, const toml::table& t, const SourceLocation& w,
                const std::string& key, PartConfig& p);
  bool read_initiator(const toml::table& dtab, const SourceLocation& dw, const std::string& dkey,
                      int dim, DetonationPoint& dp);
  static bool initiator_meets_box(const DetonationPoint& dp, const Aabb& b, int dim);
  void read_detonations(const Config& c, const toml::array& da, const SourceLocation& w,
                        const std::string& key, PartConfig& p);

  // read_dem.cpp
  void read_dem(const Config& c, const toml::table& t, const SourceLocation& w,
                const std::string& key, PartConfig& p);
  void read_packing(const Config& c, const toml::table& t, const SourceLocation& w,
                    const std::string& key, PartConfig& p);
  void read_dense_packing(const Config& c, const toml::table& pt, const SourceLocation& pw,
                          const std::string& kp, const PartConfig& p);
  void read_absorbing_walls(const toml::table& dt, const SourceLocation& dw, const std::string& key,
                            int dim, const DomainConfig& domain, DemConfig& d);
  void read_bonds(const toml::table& bt, const SourceLocation& dw, const std::string& key,
                  DemBondConfig& b);
  void read_wall_motion(const Config& c, const toml::array& ma, const SourceLocation& dw,
                        const std::string& key, DemConfig& d);
  void read_particles(const Config& c, const toml::array& pa, const SourceLocation& w,
                      const std::string& key, PartConfig& p);

  // read_fem.cpp
  void read_initial_temperature(const Config& c, const toml::table& ft, const SourceLocation& fw,
                                const std::string& key, PartConfig& p);
  void read_fem(const Config& c, const toml::table& t, const SourceLocation& w,
                const std::string& key, PartConfig& p);
  void read_fem_boundaries(const toml::array& ba, const SourceLocation& fw, const std::string& key,
                           int dim, FemConfig& f);
  void read_fem_loads(const toml::array& la, const SourceLocation& fw, const std::string& key,
                      int dim, PartConfig& p);
  void read_fem_mesh(const Config& c, const toml::table& ft, const SourceLocation& fw,
                     const std::string& key, PartConfig& p);
  void read_fem_geostatic(const Config& c, const toml::table& gt, const SourceLocation& fw,
                          const std::string& key, PartConfig& p);

  // read_contacts_probes.cpp
  void read_contacts(Config& c, const SourceLocation& top);
  // read_gauges.cpp
  void read_gauges(Config& c, const SourceLocation& top);
  void read_gauge_ids(const toml::table& t, const SourceLocation& w, const std::string& key,
                      const char* k, std::vector<std::int64_t>& out);
  void read_probes(Config& c, const SourceLocation& top);
  void read_probe_axis(Config& c, const toml::table& t, const SourceLocation& w);
  void read_lining_axis(Config& c, const toml::table& t, const SourceLocation& w);
  void read_surface_groups(const Config& c, const toml::table& t, const SourceLocation& w,
                           const std::string& key, ContactConfig& k);

  toml::table& root_;
  std::string file_;
  ErrorList errors_;
  bool domain_ok_ = true;
  Vec3 domain_min_m_{}, domain_max_m_{};  // [domain]: what a "layer" region spans across
  std::vector<std::string> c_warnings_;
};

}  // namespace crater::io::reader
