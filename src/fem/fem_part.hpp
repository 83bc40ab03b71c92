// An FEM part: an explicit Lagrangian solid (the steel plate; continuum soil) of one-point Q4
// (2D plane strain, per metre of depth) or Hex8 (3D) elements with one strength law, in the
// time loop's velocity-Verlet stages (paper section III-B; element loop in explicit_solid.hpp).
//
// Per step (Algorithm 1): advance() kicks v^{n+1/2} = v^n + a^n dt/2, imposes the boundary
// velocities and drifts x^{n+1} = x^n + v^{n+1/2} dt; compute_forces() updates the element
// stresses with d = sym grad v^{n+1/2} on x^{n+1} and gathers f_int^{n+1}; finish_step() kicks
// v^{n+1} = v^{n+1/2} + a^{n+1} dt/2. With a constant step this is the central-difference
// scheme of explicit_solid.hpp; the element state changes only when the nodes have moved, so
// compute_forces() on an unchanged state (the first call, a resumed run) changes nothing.
//
// Boundary conditions act on node sets (a face of the part's bounding box or a mesh group):
// fixed and symmetry zero velocity components, velocity imposes them, and non_reflecting adds
// Lysmer-Kuhlemeyer dashpots f = -A (rho c_p (v.n) n + rho c_s (v - (v.n) n)) with A the
// node's share of the boundary face [LK69] (c_p of the material at rest: for
// Holmquist-Johnson-Cook the elastic bulk modulus P_c/mu_c, materials::at_rest_elastic_of).
// Reactions (the forces holding imposed components) and gravity do external work; the dashpots
// dissipate (damping_j).
//
// Erosion: an element that fails (Johnson-Cook D >= 1; Holmquist-Johnson-Cook D >= 1 with
// erode_at_full_damage; the [parts.fem] erosion options) leaves the force loop; its mass share
// rho_0 V_0 / n leaves each of its nodes (with that share's kinetic energy), and its internal
// and hourglass energy leave the part's sums; all of it is reported as eroded (eroded_j, and
// the diagnostics eroded_elements and eroded_mass_kg). A node left without elements is frozen.
//
// [LK69] J. Lysmer, R. L. Kuhlemeyer, "Finite dynamic model for infinite media", J. Eng. Mech.
//        Div. ASCE 95 (1969) 859-877.
#pragma once

#include <memory>

#include "fem/settings.hpp"
#include "parts/part.hpp"

namespace crater::fem {

/// Builds the FEM part `settings` describe: a structured mesh of its box region, or the
/// elements of its mesh file.
template <int D>
std::unique_ptr<parts::Part<D>> make_fem_part(const PartSettings& settings);

}  // namespace crater::fem
