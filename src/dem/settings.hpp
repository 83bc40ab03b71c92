// Settings of a DEM part ([parts.dem], [parts.packing] and its granular material), as the
// scenario reader builds them: plain values, no strings from the file. The solver's assembly
// hands a PartSettings to make_dem_part (dem_part.hpp) and to the packing functions.
// Defaults are the schema's (io/scenario/scenario_schema.cpp), stated nowhere else: members
// are only zero-initialised (tests/io/test_defaults_once.py).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "parts/setup.hpp"

namespace crater::dem {

/// Grain material of a DEM part (model "granular").
struct GranularMaterial {
  Real shear_modulus_pa{};
  Real poisson_ratio{};
  Real friction{};
  Real restitution{};
};

/// A grain placed by hand ([[parts.dem.particles]]).
struct PlacedGrain {
  parts::Vec3 center_m{};
  Real radius_m{};
  parts::Vec3 velocity_m_s{};
};

/// Contact law of a DEM part ([parts.dem] contact). The values enter the packing cache's key.
enum class ContactLawKind { HertzMindlin, LinearSpring };

/// How a parallel bond's radius follows from the grain radii (BondRadiusRule).
enum class BondRadius { Min, Mean, Effective };

/// Parallel bonds of a DEM part (paper eqs. 17-24), made at t = 0 between touching grains.
struct BondSettings {
  bool enabled{};
  BondRadius radius_rule{};
  Real radius_multiplier{};      // \lambda [-]
  Real normal_stiffness_pa_m{};  // k̄_n [Pa/m]
  Real shear_stiffness_pa_m{};   // k̄_s [Pa/m]
  Real tensile_strength_pa{};    // \bar\sigma_c [Pa]
  Real shear_strength_pa{};      // \bar\tau_c [Pa]
  Real gap_fraction{};           // bond pairs whose gap <= this x the smaller radius
};

/// How a moving rigid wall is driven ([[parts.dem.wall_motion]]).
enum class WallDrive { Velocity, Stress };

/// A rigid wall that moves along its axis (docs/theory.md §3, moving walls): at a given normal
/// velocity, or by the servo that holds the mean normal stress it exerts on the grains.
struct WallMotion {
  parts::Face face{};
  std::optional<Real> position_m;  // the plane's coordinate at t = 0; unset: the domain's face
  WallDrive drive{};
  Real velocity_m_s{};   // Velocity: along the face's outward normal (> 0: the box grows)
  Real ramp_s{};         // Velocity: reached linearly over this time after start_s
  Real stress_pa{};      // Stress: the target compressive stress sigma* [Pa]
  Real servo_gain{};     // Stress: alpha, the fraction of the force error closed per step
  Real max_speed_m_s{};  // Stress: cap on the wall's speed
  Real start_s{};        // the wall moves from start_s ...
  Real end_s{};          // ... to end_s (the reader sets +inf when unset)
};

/// Numerics and walls of a DEM part ([parts.dem]).
struct Settings {
  ContactLawKind contact{};
  bool hertz_row_of_spheres{};     // 2D hertz_mindlin: disks as rows of spheres (hertz_2d)
  Real normal_stiffness_n_m{};     // linear_spring: k_n [N/m] (per metre of depth in 2D)
  Real shear_stiffness_n_m{};      // linear_spring: k_s [N/m]
  Real stiffness_step_fraction{};  // stable step = this x sqrt(m_min / k_max)
  Real radius_min_m{};
  Real radius_max_m{};
  std::uint64_t seed{};
  Real local_damping{};
  Real rayleigh_fraction{};
  Real rolling_friction{};  // \mu_r [-], 0: off
  Real rolling_damping{};   // \eta_r [-]
  bool rate_dependent_friction{};
  Real friction_rate_beta{};              // \beta [-]
  Real friction_reference_strain_rate{};  // \dot\varepsilon_0 [1/s]
  std::vector<parts::Face> walls;
  Real wall_friction{};
  Real wall_restitution{};
  std::vector<WallMotion> wall_motion;  // walls of `walls` that move, at most one per face
  // Absorbing (viscous, Lysmer-Kuhlemeyer) walls: faces holding the grains' static reaction
  // of t = 0 plus dashpots of the bed's impedance (docs/theory.md §3).
  std::vector<parts::Face> absorbing_walls;
  Real absorbing_density_kg_m3{};     // rho_b of the bed; 0: grain mass / region volume
  Real absorbing_p_wave_speed_m_s{};  // c_p; 0: linear_spring estimate 2r sqrt(k_n / m)
  Real absorbing_s_wave_speed_m_s{};  // c_s; 0: c_p sqrt((1 - 2 nu) / (2 - 2 nu))
  BondSettings bonds;
  std::vector<PlacedGrain> particles;  // placed by hand; empty: the region's lattice
};

/// How a DEM part's grains are laid out ([parts.packing]).
/// How a packed part's grains are laid ([parts.packing] method).
enum class PackingMethod { Lattice, Random, Dense };

struct PackingSettings {
  PackingMethod method{};
  Real porosity = 0.4;  // no schema default (random needs it); 0.4 enters lattice packings' key
  std::vector<Real> sieve_diameter_m;  // empty: radii uniform in [radius_min_m, radius_max_m]
  std::vector<Real> sieve_passing;
  bool settle{};
  Real settle_kinetic_ratio{};
  Real settle_max_time_s{};
  Real settle_damping{};
  Real settle_safety_factor{};     // of the stable step while settling; 0: [time] safety_factor
  Real settle_unbalanced_ratio{};  // dense: settled when sum |F| / sum m g is below this
  std::string cache_dir;           // absolute, or relative to the working directory
  Real agitation_m_s{};            // random initial velocity, uniform in +-this per component
};

/// Everything a DEM part is built from.
struct PartSettings {
  parts::PartSetup part;
  Settings dem;
  PackingSettings packing;
  GranularMaterial grain;
  Real rho0_kg_m3{};     // the grains' density
  Real safety_factor{};  // of the stable step, while settling (settle_safety_factor, else [time]'s)
};

}  // namespace crater::dem
