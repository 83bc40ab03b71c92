// The element loop of the explicit Lagrangian solid (paper §III-B): per element, uniform
// strain kinematics, objective stress update through the block's strength law (Holmquist-
// Johnson-Cook with its compaction state per element), Johnson-Cook or HJC damage and erosion,
// bulk viscosity, Flanagan-Belytschko hourglass control; then nodal internal forces gathered
// per node; lumped masses; stable step.
//
// Central-difference step as the caller runs it (Algorithm 1 of the paper):
//   a^n = (f_ext^n + f_int^n) / m,   v^{n+1/2} = v^{n-1/2} + \Delta t a^n   (boundary conditions)
//   x^{n+1} = x^n + \Delta t v^{n+1/2}
//   compute_internal_forces(mesh, material, \Delta t)   // uses x^{n+1} and v^{n+1/2}
// The gradients are evaluated on x^{n+1} for both the strain increment d \Delta t and the forces
// f_{iI} = -V (\sigma_{ij} - q \delta_{ij}) b_{jI} + f^{hg}_{iI}  [FB81 eq. 19].
// The internal energy increment of an element is V \Delta t (\sigma_n + \sigma_{n+1})/2 : d
// - q V \Delta t tr d (trapezoidal in the stress); hourglass energy \Delta t \sum Q g.
#pragma once

#include <limits>
#include <optional>

#include "core/types.hpp"
#include "fem/bulk_viscosity.hpp"
#include "fem/explicit_mesh.hpp"
#include "fem/hourglass.hpp"
#include "materials/damage/johnson_cook_damage.hpp"
#include "materials/strength/strength.hpp"

namespace crater::fem {

/// Everything the element loop needs to know about the block's material.
struct SolidMaterial {
  materials::StrengthParams strength = materials::ElasticParams{};
  std::optional<materials::JohnsonCookDamageParams> damage;  // none: no damage, no erosion
  // Holmquist-Johnson-Cook: an element whose HJC damage reaches 1 erodes (as Johnson-Cook damage
  // with `damage` set); false: it stays, with the strength of comminuted concrete (B P*^N).
  bool erode_at_full_damage = false;
  Real density_kg_m3 = 0;  // reference density \rho_0
  Real initial_temperature_k = 293.15;
  HourglassParams hourglass;
  BulkViscosityParams bulk_viscosity;
  // Erosion besides Johnson-Cook damage (as LS-DYNA's *MAT_ADD_EROSION / ERODE options):
  Real erosion_plastic_strain = std::numeric_limits<Real>::infinity();  // erode at this eps_p
  bool erode_inverted = false;  // an element turned inside out erodes instead of failing
  // An element whose own stable step falls below this erodes (LS-DYNA's ERODE = 1 with
  // *CONTROL_TERMINATION's DTMIN); 0: never. Set by the part from erosion_step_ratio.
  Real erosion_min_step_s = 0;
  // Selective mass scaling (LS-DYNA's DT2MS < 0): an element whose stable step falls below this
  // gains the mass that holds its step at it, shared equally by its nodes (momentum kept); 0:
  // never. Set by the part from mass_scaling_step_ratio.
  Real mass_scaling_min_step_s = 0;
};

/// What one force evaluation reports (sums in a fixed order: bit-identical for any thread count).
struct ForceReport {
  Real internal_energy_increment_j = 0;
  Real hourglass_energy_increment_j = 0;
  Real stable_dt_s = 0;         // smallest element step L_e / (Q + sqrt(Q^2 + c^2))
  Index limiting_element = -1;  // element giving stable_dt_s
  Index newly_eroded = 0;       // elements that failed during this evaluation
  Index inverted_element = -1;  // an element with V <= 0 (numerical failure), or -1
  // Mass scaling in this evaluation: mass added to the nodes [kg], the kinetic energy the nodes
  // gave up by keeping their momentum [J] (an inelastic pick-up of mass at rest), and the first
  // element (lowest number) that gained mass, or -1.
  Real mass_added_kg = 0;
  Real mass_scaling_dissipated_j = 0;
  Index first_mass_scaled_element = -1;
};

/// Sizes the element state, computes reference volumes, lumped masses m_I = \sum_e \rho_0 V_e / n
/// and the node adjacency; zero stress, room temperature. Positions must be set.
template <int D>
void initialise(ExplicitMesh<D>& mesh, const SolidMaterial& material);

/// The node -> (element, local node) adjacency of the mesh's connectivity (node_entry_offsets,
/// node_entries), in element order.
template <int D>
void build_node_adjacency(ExplicitMesh<D>& mesh);

/// One evaluation of the internal forces (header comment): updates the element state and
/// mesh.internal_force. dt is the step just taken (0 for the initial evaluation).
template <int D>
ForceReport compute_internal_forces(ExplicitMesh<D>& mesh, const SolidMaterial& material, Real dt);

/// Stable step of the block in its current configuration without bulk viscosity:
/// min_e L_e / c_d [s] (c_d at each element's current density; mass scaling not counted).
template <int D>
Real stable_time_step(const ExplicitMesh<D>& mesh, const SolidMaterial& material);

/// Kinetic energy \sum m v^2 / 2 [J].
template <int D>
Real kinetic_energy(const ExplicitMesh<D>& mesh);

}  // namespace crater::fem
