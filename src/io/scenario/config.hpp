// The validated, immutable description of a run, as the scenario reader builds it. The
// methods never see it: each owns its settings (sph/, dem/, fem/ settings.hpp, below io), and
// the solver's assembly (solver/assembly.hpp) builds each part's settings from it. Vectors are
// stored with 3 entries; only the first `dimension` are meaningful. Defaults are stated once, in
// the schema (scenario_schema.cpp, material_laws.cpp): the reader sets every member from the
// validated table, and members are only zero-initialised here (tests/io/test_defaults_once.py).
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "dem/settings.hpp"
#include "fem/settings.hpp"
#include "materials/eos/eos.hpp"
#include "parts/region.hpp"
#include "parts/setup.hpp"
#include "sph/settings.hpp"

namespace crater::io {

using parts::Vec3;

struct TimeConfig {
  Real safety_factor{};
  std::optional<Real> fixed_dt_s;
  SourceLocation fixed_dt_where;  // for the "step above the stable limit" error
  // The run stops (exit 3, the limiting part and entity named) when the step falls below this
  // (a collapsing element or particle would otherwise hold the run at a crawl); unset: never.
  std::optional<Real> min_dt_s;
  Index max_steps{};  // 0: no limit
  // Multi-rate stepping (solver/multi_rate.hpp): on, and the largest ratio of a part's step
  // to the smallest (a power of two).
  bool multi_rate{};
  Index multi_rate_max_ratio{};
  // The energy guard: relative balance errors (history.csv energy_error) at which the run
  // warns once and at which it stops (exit 3); 0 turns either off.
  Real energy_warn_error{};
  Real energy_stop_error{};
};

enum class VtuEncoding { Appended, Base64 };
/// How a frame of a part spread over MPI ranks is written: one VTU gathered by rank 0, or one
/// piece per rank under a PVTU (output.pieces).
enum class FramePieces { Gathered, Ranks };

struct OutputConfig {
  Real interval_s{};
  Index history_every{};
  bool vtu{};
  VtuEncoding vtu_encoding{};
  FramePieces pieces{};
  Index checkpoint_every_steps{};  // 0: not by step count
  Real checkpoint_every_s{};       // wall-clock seconds; 0: not by time
  Index checkpoint_keep{};         // newest checkpoints kept in <out>/checkpoints
  bool checkpoint_at_end{};        // a checkpoint of the last state (a run can be extended)
  Index gauges_every_steps{};      // a gauges.csv row every this many steps (and at frames)
  Index max_frames{};              // more VTU frames than this is an input error
  Real max_bytes{};                // VTU bytes the run may write in all
  Real memory_limit_fraction{};    // of the available memory the run's estimate may take
  SourceLocation interval_where;   // for the cadence errors
  bool interval_given{};           // interval_s was set (else end_time_s / 20)
};

using parts::Face;
using parts::Outflow;
using DomainConfig = parts::Domain;
using dem::GranularMaterial;
using SolidMaterialConfig = fem::MaterialSettings;

struct MaterialConfig {
  std::string name;
  std::string model;          // "jwl", "ideal_gas", "tait", "granular", "elastic", ...
  materials::EosParams eos;   // SPH materials
  GranularMaterial granular;  // DEM materials (model "granular")
  SolidMaterialConfig solid;  // FEM materials
  Real rho0_kg_m3{};
  SourceLocation where;
};

using parts::RegionConfig;
using parts::RegionType;

using InitialConfig = parts::InitialState;
using ZoneConfig = parts::Zone;
using SphConfig = sph::Settings;
using DemParticle = dem::PlacedGrain;
using DemContact = dem::ContactLawKind;
using dem::BondRadius;
using DemBondConfig = dem::BondSettings;
using DemConfig = dem::Settings;
using PackingConfig = dem::PackingSettings;
using FemBoundaryType = fem::BoundaryType;
using FemBoundaryConfig = fem::BoundarySettings;
using FemLoadType = fem::LoadType;
using FemLoadConfig = fem::LoadSettings;
using GeostaticConfig = fem::GeostaticSettings;
using FemConfig = fem::Settings;
using parts::DetonationPoint;

/// A part's discretisation; the scenario's `method` key, mapped once by the reader.
enum class Method { Sph, Dem, Fem };

/// "sph", "dem" or "fem": the key's value, for messages.
inline const char* method_name(Method m) {
  switch (m) {
    case Method::Sph:
      return "sph";
    case Method::Dem:
      return "dem";
    case Method::Fem:
      return "fem";
  }
  throw std::logic_error("method_name: not a Method");
}

/// A DEM part's settings: its grains' ([parts.dem]) and their packing ([parts.packing]).
struct DemPartConfig {
  DemConfig dem;
  PackingConfig packing;
};

/// The settings of one method, alternatives in the order of Method: the alternative held is
/// the part's method (one source of truth, no second member to disagree with it).
using MethodConfig = std::variant<SphConfig, DemPartConfig, FemConfig>;
// PartConfig::method() reads the index: the alternatives stay in Method's order.
template <Method M>
using MethodSettings = std::variant_alternative_t<static_cast<std::size_t>(M), MethodConfig>;
static_assert(std::is_same_v<MethodSettings<Method::Sph>, SphConfig> &&
              std::is_same_v<MethodSettings<Method::Dem>, DemPartConfig> &&
              std::is_same_v<MethodSettings<Method::Fem>, FemConfig>);

struct PartConfig {
  std::string name;
  MethodConfig settings;   // its method's settings only; method() is which
  std::size_t material{};  // index into Config::materials
  Real spacing_m{};
  RegionConfig region;
  InitialConfig initial;
  std::vector<ZoneConfig> zones;
  std::vector<std::size_t> carve;  // parts whose regions this part's particles leave empty
  std::vector<DetonationPoint> detonations;
  SourceLocation where;
  // Size estimated when the scenario is loaded, before anything is built (the memory check of
  // solver/memory_estimate.hpp): particles, grains or elements, no-slip wall particles (sph),
  // and the key that sets the count (e.g. "parts.soil.spacing_m") with its place in the input.
  Real estimated_count{};
  Real estimated_wall_count{};
  std::string resolution_key;
  SourceLocation resolution_where;

  Method method() const { return static_cast<Method>(settings.index()); }
  bool is(Method m) const { return method() == m; }
  // Another method's settings are not there: asking for them is a logic error
  // (std::bad_variant_access), not a row of zeros.
  const SphConfig& sph() const { return std::get<SphConfig>(settings); }
  SphConfig& sph() { return std::get<SphConfig>(settings); }
  const DemConfig& dem() const { return std::get<DemPartConfig>(settings).dem; }
  DemConfig& dem() { return std::get<DemPartConfig>(settings).dem; }
  const PackingConfig& packing() const { return std::get<DemPartConfig>(settings).packing; }
  PackingConfig& packing() { return std::get<DemPartConfig>(settings).packing; }
  const FemConfig& fem() const { return std::get<FemConfig>(settings); }
  FemConfig& fem() { return std::get<FemConfig>(settings); }
};

/// A contact between two parts ([[contacts]]): penalty forces, equal and opposite.
struct ContactConfig {
  std::array<std::size_t, 2> parts{};  // indices into Config::parts
  Real penalty_scale{};                // s of the penalty stiffness
  Real friction{};                     // Coulomb coefficient between the two parts
  Real damping_ratio{};                // fraction of critical damping of the normal penalty
  // Per part (as `parts`): the mesh group the contact is restricted to; empty: the whole surface
  std::array<std::string, 2> surface_groups{};
  SourceLocation where;
};

/// [[gauges]]: fields of one part at chosen entities, written to gauges.csv
/// (src/solver/gauges.hpp).
struct GaugeConfig {
  std::string name;
  std::size_t part{};                     // index into Config::parts
  std::optional<Vec3> point_m;            // the entities nearest this point at t = 0
  std::vector<std::int64_t> ids;          // node (FEM) or particle (SPH, DEM: their id field) ids
  std::vector<std::int64_t> element_ids;  // FEM elements (for cell fields)
  std::optional<parts::Face> face;        // FEM: the nodes on this face of the part at t = 0
  bool sum{};                             // one value per field: the sum over the entities
  std::vector<std::string> fields;
  SourceLocation where;
};

/// The paper's measurements ([probes]); see src/solver/probes.hpp.
struct ProbesConfig {
  std::optional<std::size_t> plate;  // an fem part (index into Config::parts)
  std::optional<std::size_t> soil;   // a dem part
  Real stress_time_s{};
  std::optional<Real> surface_bin_m;
  // 3D: the horizontal position [x, y] of the crater's axis [m], about which the surface
  // profile is averaged. From axis_m, else the first detonation point of the first SPH part
  // that has one, else the full model's horizontal centre (on the symmetry planes the domain
  // has). Unused in 2D.
  std::array<Real, 2> axis_m{};
  // A tunnel's lining (an fem part; src/solver/lining_probe.hpp), its axis through
  // lining_axis_point_m along lining_axis_direction (3D; 2D: perpendicular to the plane).
  std::optional<std::size_t> lining;
  // The soil around it (an fem part): its displacement along the crown line.
  std::optional<std::size_t> lining_soil;
  std::array<Real, 3> lining_axis_point_m{};
  std::array<Real, 3> lining_axis_direction{0, 1, 0};
  bool any() const { return plate || soil || lining; }
};

struct Config {
  std::string file;  // path of the scenario file
  std::string hash;  // FNV-1a 64 of the effective (defaults filled) scenario, hex
  // The same, less the keys a continued run may change (kRunControlKeys in load.cpp: the end
  // time, the step cap, the guards, the outputs other than their interval): what a checkpoint
  // must match to be resumed by this scenario.
  std::string state_hash;
  std::string name;
  std::string description;
  int dimension{};
  Real end_time_s{};
  TimeConfig time;
  OutputConfig output;
  DomainConfig domain;
  std::vector<MaterialConfig> materials;
  std::vector<PartConfig> parts;
  std::vector<ContactConfig> contacts;
  ProbesConfig probes;
  std::vector<GaugeConfig> gauges;
  std::string level;  // the [levels.<name>] applied (--level), or empty
  struct LevelInfo {
    std::string name, description;
  };
  std::vector<LevelInfo> levels;      // every level the file defines
  std::vector<std::string> warnings;  // non-fatal remarks shown by check and run
  std::string effective_toml;         // the scenario with defaults filled in
};

}  // namespace crater::io
