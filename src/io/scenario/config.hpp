// The validated, immutable description of a run. Physics code sees only this, never strings
// from the file or TOML nodes. Vectors are stored with 3 entries; only the first `dimension`
// are meaningful.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "materials/damage/johnson_cook_damage.hpp"
#include "materials/eos/eos.hpp"
#include "materials/strength/strength.hpp"
#include "mesh/gmsh.hpp"
#include "parts/region.hpp"
#include "sph/kernels.hpp"

namespace crater::io {

using parts::Vec3;

struct TimeConfig {
  Real safety_factor = 0.9;
  std::optional<Real> fixed_dt_s;
  SourceLocation fixed_dt_where;  // for the "step above the stable limit" error
  Index max_steps = 0;            // 0: no limit
  // The energy guard: relative balance errors (history.csv energy_error) at which the run
  // warns once and at which it stops (exit 3); 0 turns either off.
  Real energy_warn_error = 0.02;
  Real energy_stop_error = 0.2;
};

enum class VtuEncoding { Appended, Base64 };

struct OutputConfig {
  Real interval_s = 0;
  Index history_every = 10;
  bool vtu = true;
  VtuEncoding vtu_encoding = VtuEncoding::Appended;
  Index checkpoint_every_steps = 0;  // 0: not by step count
  Real checkpoint_every_s = 120;     // wall-clock seconds; 0: not by time
  Index checkpoint_keep = 2;         // newest checkpoints kept in <out>/checkpoints
  Index max_frames = 10000;          // more VTU frames than this is an input error
  Real max_bytes = 50e9;             // VTU bytes the run may write in all
  Real memory_limit_fraction = 0.8;  // of the available memory the run's estimate may take
  SourceLocation interval_where;     // for the cadence errors
};

/// What happens to a particle (SPH or DEM) that leaves the domain box: the run stops (exit 3),
/// or the particle is removed at the end of the step and booked as having left.
enum class Outflow { Stop, Remove };

struct DomainConfig {
  Vec3 min_m{};
  Vec3 max_m{};
  Vec3 gravity_m_s2{};
  Outflow outflow = Outflow::Stop;
};

/// Grain material of a DEM part (model "granular").
struct GranularMaterial {
  Real shear_modulus_pa = 0;
  Real poisson_ratio = 0;
  Real friction = 0;
  Real restitution = 1;
};

/// Solid material of an FEM part (models "elastic", "johnson_cook", "drucker_prager").
struct SolidMaterialConfig {
  materials::StrengthParams strength = materials::ElasticParams{};
  std::optional<materials::JohnsonCookDamageParams> damage;  // [materials.damage]; none: no erosion
};

struct MaterialConfig {
  std::string name;
  std::string model;          // "jwl", "ideal_gas", "tait", "granular", "elastic", ...
  materials::EosParams eos;   // SPH materials
  GranularMaterial granular;  // DEM materials (model "granular")
  SolidMaterialConfig solid;  // FEM materials
  Real rho0_kg_m3 = 0;
  SourceLocation where;
};

using parts::RegionConfig;
using parts::RegionType;

struct InitialConfig {
  std::optional<Real> density_kg_m3;
  std::optional<Real> pressure_pa;
  Vec3 velocity_m_s{};
};

/// A sub-region with its own initial state; unset values fall back to the part's.
struct ZoneConfig {
  RegionConfig region;
  std::optional<Real> spacing_m;  // own lattice pitch (unset: the part's lattice)
  std::optional<Real> density_kg_m3;
  std::optional<Real> pressure_pa;
  std::optional<Vec3> velocity_m_s;
};

/// Faces of the domain box, for walls: 2*axis + (0 = min side, 1 = max side).
enum class Face { Left = 0, Right = 1, Bottom = 2, Top = 3, Back = 4, Front = 5 };

struct SphConfig {
  sph::KernelKind kernel = sph::KernelKind::WendlandC2;
  Real h_factor = 1.3;
  Real av_alpha = 1.0;
  Real av_beta = 2.0;
  Real cfl = 0.3;
  bool variable_h = true;
  Real xsph_epsilon = 0;
  Real tensile_epsilon = 0;
  Real viscosity_pa_s = 0;
  std::vector<Face> walls;
  int wall_layers = 3;
  bool wall_no_slip = false;
};

struct DemParticle {
  Vec3 center_m{};
  Real radius_m = 0;
  Vec3 velocity_m_s{};
};

/// Contact law of a DEM part ([parts.dem] contact).
enum class DemContact { HertzMindlin, LinearSpring };

/// How a parallel bond's radius follows from the grain radii (dem::BondRadiusRule).
enum class BondRadius { Min, Mean, Effective };

/// Parallel bonds of a DEM part (paper eqs. 17-24), made at t = 0 between touching grains.
struct DemBondConfig {
  bool enabled = false;
  BondRadius radius_rule = BondRadius::Min;
  Real radius_multiplier = 1.0;    // \lambda [-]
  Real normal_stiffness_pa_m = 0;  // k̄_n [Pa/m]
  Real shear_stiffness_pa_m = 0;   // k̄_s [Pa/m]
  Real tensile_strength_pa = 0;    // \bar\sigma_c [Pa]
  Real shear_strength_pa = 0;      // \bar\tau_c [Pa]
  Real gap_fraction = 0.01;        // bond pairs whose gap <= this x the smaller radius
};

struct DemConfig {
  DemContact contact = DemContact::HertzMindlin;
  bool hertz_row_of_spheres = false;    // 2D hertz_mindlin: disks as rows of spheres (hertz_2d)
  Real normal_stiffness_n_m = 0;        // linear_spring: k_n [N/m] (per metre of depth in 2D)
  Real shear_stiffness_n_m = 0;         // linear_spring: k_s [N/m]
  Real stiffness_step_fraction = 0.17;  // stable step = this x sqrt(m_min / k_max)
  Real radius_min_m = 0;
  Real radius_max_m = 0;
  std::uint64_t seed = 1;
  Real local_damping = 0;
  Real rayleigh_fraction = 0.25;
  Real rolling_friction = 0;  // \mu_r [-], 0: off
  Real rolling_damping = 0;   // \eta_r [-]
  bool rate_dependent_friction = false;
  Real friction_rate_beta = 0.05;             // \beta [-]
  Real friction_reference_strain_rate = 1.0;  // \dot\varepsilon_0 [1/s]
  std::vector<Face> walls;
  Real wall_friction = 0.5;
  Real wall_restitution = 0.5;
  // Absorbing (viscous, Lysmer-Kuhlemeyer) walls: faces holding the grains' static reaction
  // of t = 0 plus dashpots of the bed's impedance (docs/theory.md §3).
  std::vector<Face> absorbing_walls;
  Real absorbing_density_kg_m3 = 0;     // rho_b of the bed; 0: grain mass / region volume
  Real absorbing_p_wave_speed_m_s = 0;  // c_p; 0: linear_spring estimate 2r sqrt(k_n / m)
  Real absorbing_s_wave_speed_m_s = 0;  // c_s; 0: c_p sqrt((1 - 2 nu) / (2 - 2 nu))
  DemBondConfig bonds;
  std::vector<DemParticle> particles;  // placed by hand; empty: the region's lattice
};

/// How a DEM part's grains are laid out ([parts.packing]).
struct PackingConfig {
  bool random = false;  // false: lattice
  Real porosity = 0.4;
  std::vector<Real> sieve_diameter_m;  // empty: radii uniform in [radius_min_m, radius_max_m]
  std::vector<Real> sieve_passing;
  bool settle = false;
  Real settle_kinetic_ratio = 1e-4;
  Real settle_max_time_s = 2.0;
  Real settle_damping = 0.7;
  std::string cache_dir;   // absolute, or relative to the working directory
  Real agitation_m_s = 0;  // random initial velocity, uniform in +-this per component
};

/// How the nodes of an FEM boundary condition are chosen and what is imposed on them.
enum class FemBoundaryType { Fixed, Symmetry, Velocity, NonReflecting };

struct FemBoundaryConfig {
  FemBoundaryType type = FemBoundaryType::Fixed;
  std::optional<Face> face;                          // a face of the part's bounding box
  std::string group;                                 // or a physical group of the mesh file
  Vec3 velocity_m_s{};                               // Velocity: imposed components
  std::array<bool, 3> components{true, true, true};  // Velocity: which components are imposed
  SourceLocation where;
};

/// A load on boundary faces of an FEM part ([[parts.fem.loads]]). type "pressure": a pressure
/// history p(t) (linear between the table's points, zero outside), positive into the body,
/// on the current (deformed) faces of one face of the part's bounding box, optionally only
/// those whose centre lies in a box (its extent along the face normal is not used).
enum class FemLoadType { Pressure };

struct FemLoadConfig {
  FemLoadType type = FemLoadType::Pressure;
  Face face = Face::Bottom;
  std::optional<RegionConfig> region;  // a box; unset: the whole face
  std::vector<Real> time_s;            // strictly increasing
  std::vector<Real> pressure_pa;       // same length
  SourceLocation where;
};

/// Numerics of an FEM part ([parts.fem]).
struct FemConfig {
  bool hourglass_stiffness = false;  // false: viscous form
  Real hourglass_coefficient = 0.1;
  Real bulk_viscosity_quadratic = 1.5;
  Real bulk_viscosity_linear = 0.06;
  Real initial_temperature_k = 293.15;
  std::optional<Real> erosion_plastic_strain;  // erode elements at this plastic strain
  bool erode_inverted = false;                 // inverted elements erode (else: exit 3)
  Real erosion_step_ratio = 0;  // erode elements whose step < this x the part's initial step
  std::vector<FemBoundaryConfig> boundaries;
  std::vector<FemLoadConfig> loads;
  std::string mesh_file;   // Gmsh .msh 4.1; empty: structured mesh of the region box
  std::string mesh_group;  // physical group of the elements in mesh_file; empty: all
  std::shared_ptr<const mesh::GmshMesh> mesh;  // mesh_file as read when the scenario was loaded
};

struct DetonationPoint {
  Vec3 point_m{};
  Real time_s = 0;
};

struct PartConfig {
  std::string name;
  std::string method;        // "sph", "dem" or "fem"
  std::size_t material = 0;  // index into Config::materials
  Real spacing_m = 0;
  RegionConfig region;
  InitialConfig initial;
  std::vector<ZoneConfig> zones;
  std::vector<std::size_t> carve;  // parts whose regions this part's particles leave empty
  SphConfig sph;
  DemConfig dem;
  PackingConfig packing;
  FemConfig fem;
  std::vector<DetonationPoint> detonations;
  SourceLocation where;
  // Size estimated when the scenario is loaded, before anything is built (the memory check of
  // solver/memory_estimate.hpp): particles, grains or elements, no-slip wall particles (sph),
  // and the key that sets the count (e.g. "parts.soil.spacing_m") with its place in the input.
  Real estimated_count = 0;
  Real estimated_wall_count = 0;
  std::string resolution_key;
  SourceLocation resolution_where;
};

/// A contact between two parts ([[contacts]]): penalty forces, equal and opposite.
struct ContactConfig {
  std::array<std::size_t, 2> parts{};  // indices into Config::parts
  Real penalty_scale = 1.0;            // s of the penalty stiffness
  Real friction = 0;                   // Coulomb coefficient between the two parts
  Real damping_ratio = 0.1;            // fraction of critical damping of the normal penalty
  SourceLocation where;
};

/// The paper's measurements ([probes]); see src/solver/probes.hpp.
struct ProbesConfig {
  std::optional<std::size_t> plate;  // an fem part (index into Config::parts)
  std::optional<std::size_t> soil;   // a dem part
  Real stress_time_s = 6e-4;
  std::optional<Real> surface_bin_m;
  bool any() const { return plate || soil; }
};

struct Config {
  std::string file;  // path of the scenario file
  std::string hash;  // FNV-1a 64 of the effective (defaults filled) scenario, hex
  std::string name;
  std::string description;
  int dimension = 2;
  Real end_time_s = 0;
  TimeConfig time;
  OutputConfig output;
  DomainConfig domain;
  std::vector<MaterialConfig> materials;
  std::vector<PartConfig> parts;
  std::vector<ContactConfig> contacts;
  ProbesConfig probes;
  std::string level;  // the [levels.<name>] applied (--level), or empty
  struct LevelInfo {
    std::string name, description;
  };
  std::vector<LevelInfo> levels;      // every level the file defines
  std::vector<std::string> warnings;  // non-fatal remarks shown by check and run
  std::string effective_toml;         // the scenario with defaults filled in
};

/// The regions of the parts that `carve` names (indices into config.parts), for parts::carved.
inline std::vector<RegionConfig> carving_regions(const Config& config,
                                                 const std::vector<std::size_t>& carve) {
  std::vector<RegionConfig> regions;
  for (std::size_t k : carve)
    regions.push_back(config.parts[k].region);
  return regions;
}

}  // namespace crater::io
