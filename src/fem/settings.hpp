// Settings of an FEM part ([parts.fem] and its solid material), as the scenario reader builds
// them: plain values and the mesh file as read, no strings from the file. The solver's
// assembly hands a PartSettings to make_fem_part (fem_part.hpp).
// Defaults are the schema's (io/scenario/scenario_schema.cpp), stated nowhere else: members
// are only zero-initialised (tests/io/test_defaults_once.py).
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "materials/damage/johnson_cook_damage.hpp"
#include "materials/strength/strength.hpp"
#include "mesh/solid_mesh.hpp"
#include "parts/setup.hpp"

namespace crater::fem {

/// Solid material of an FEM part (models "elastic", "johnson_cook", "drucker_prager",
/// "holmquist_johnson_cook").
struct MaterialSettings {
  materials::StrengthParams strength{};
  std::optional<materials::JohnsonCookDamageParams> damage;  // [materials.damage]; none: no erosion
  bool erode_at_full_damage{};  // holmquist_johnson_cook: elements erode when D reaches 1
};

/// How the nodes of an FEM boundary condition are chosen and what is imposed on them.
enum class BoundaryType { Fixed, Symmetry, Velocity, NonReflecting };

struct BoundarySettings {
  BoundaryType type{};
  std::optional<parts::Face> face;                   // a face of the part's bounding box
  std::string group;                                 // or a physical group of the mesh file
  parts::Vec3 velocity_m_s{};                        // Velocity: imposed components
  std::array<bool, 3> components{true, true, true};  // Velocity: which components are imposed
  SourceLocation where;
};

/// A load on boundary faces of an FEM part ([[parts.fem.loads]]). type "pressure": a pressure
/// history p(t) (linear between the table's points, zero outside), positive into the body,
/// on the current (deformed) faces of one face of the part's bounding box, optionally only
/// those whose centre lies in a box (its extent along the face normal is not used).
enum class LoadType { Pressure };

struct LoadSettings {
  LoadType type{};
  parts::Face face{};
  std::string group;                          // a physical group of the mesh file instead of face
  std::optional<parts::RegionConfig> region;  // a box; unset: the whole face
  std::vector<Real> time_s;                   // strictly increasing
  std::vector<Real> pressure_pa;              // same length
  SourceLocation where;
};

/// The initial geostatic stress of an FEM part ([parts.fem] geostatic; fem/geostatic.hpp): at
/// t = 0 each element's stress is \sigma_v = -\rho_0 g\,depth on gravity's axis and
/// \sigma_h = K_0 \sigma_v on the others (tension positive), zero above the surface.
struct GeostaticSettings {
  Real surface_m{};        // coordinate of the free ground surface on gravity's axis [m]
  std::optional<Real> k0;  // lateral earth pressure coefficient K_0 [-]; unset: \nu / (1 - \nu)
};

/// [[parts.fem.rigid_walls]]: a fixed plane the nodes cannot cross (fem/boundaries.hpp).
struct RigidWallSettings {
  parts::Vec3 point_m{};
  parts::Vec3 normal{};  // towards the part's side; any length but zero
  Real friction{};
  SourceLocation where;
};

/// Numerics, boundaries and mesh of an FEM part ([parts.fem]).
struct Settings {
  bool hourglass_stiffness{};  // false: viscous form
  Real hourglass_coefficient{};
  Real bulk_viscosity_quadratic{};
  Real bulk_viscosity_linear{};
  Real initial_temperature_k{};
  std::optional<Real> erosion_plastic_strain;  // erode elements at this plastic strain
  bool erode_inverted{};                       // inverted elements erode (else: exit 3)
  Real erosion_step_ratio{};  // erode elements whose step < this x the part's initial step
  // Selective mass scaling: elements whose step < this x the part's initial step gain mass to
  // keep it (0: off); the run stops (exit 3) when the added mass passes mass_scaling_limit x
  // the part's initial mass.
  Real mass_scaling_step_ratio{};
  Real mass_scaling_limit{};
  std::vector<BoundarySettings> boundaries;
  std::vector<RigidWallSettings> rigid_walls;
  std::vector<LoadSettings> loads;
  std::optional<GeostaticSettings> geostatic;  // unset: the part starts unstressed
  std::string mesh_file;   // Gmsh .msh 4.1; empty: structured mesh of the region box
  std::string mesh_group;  // physical group of the elements in mesh_file; empty: all
  // The part's elements in mesh_file, taken from it once when the scenario was read.
  std::shared_ptr<const mesh::SolidElements> elements;
};

/// Everything an FEM part is built from.
struct PartSettings {
  parts::PartSetup part;
  Settings fem;
  MaterialSettings material;
  Real rho0_kg_m3{};  // the material's reference density
};

}  // namespace crater::fem
