// The initial geostatic stress of an FEM part ([parts.fem] geostatic): the state of a ground at
// rest under its own weight, set once at t = 0 so that a soil column does not first fall and
// ring before anything else happens.
//
// With gravity g along one axis and the free surface at coordinate s on it, a point at depth
// d = (x - s) sgn(g_axis) below the surface carries (tension positive, as every strength law
// here; [P02] ch. 3, [TG70] for the elastic ratio)
//   \sigma_v = -\rho_0 |g| d                   on gravity's axis               [Pa]
//   \sigma_h = K_0 \sigma_v                    on the other axes (2D: x and the plane-strain z)
//   \tau = 0,     and \sigma = 0 where d <= 0 (above the surface).
// K_0, the coefficient of lateral earth pressure at rest, is an input; unset, it is that of an
// elastic layer loaded in uniaxial strain (\varepsilon_h = 0 in Hooke's law),
//   K_0 = \nu / (1 - \nu);
// for a normally consolidated sand Jaky's K_0 = 1 - \sin\phi [J44] is the usual value.
//
// One-point elements (explicit_solid.hpp) carry one stress, sampled here at the element's
// integration point \xi = 0, the mean of its nodes. On a mesh of boxes with faces normal to the
// axes (the structured mesh; layers of any heights h_a above and h_b below a node) this stress
// is in exact nodal equilibrium with the lumped weights: the stress jump between two layers,
// \rho_0 |g| (h_a + h_b)/2, times the node's share of the face area is the weight of the node's
// lumped mass, and at the surface the top layer's \rho_0 |g| h/2 carries the top nodes' half
// layer. The part then stays at rest to rounding if its base is supported and its sides are
// held normal to themselves (symmetry or fixed), as the state assumes (no lateral strain). On
// other meshes the state is close to equilibrium and the part settles by small motions.
//
// The material's yield surface is not consulted to build the state: a state outside it (e.g.
// Drucker-Prager with K_0 below the active limit, for the compression cone of a cohesionless
// soil K_a = (1 - \sin\phi)/(1 + \sin\phi)) is returned onto the surface by the law in the first
// step, with plastic flow; apply_geostatic_stress counts such elements and warns.
//
// References
//   [J44]  J. Jaky, "The coefficient of earth pressure at rest", J. Soc. Hungarian Architects
//          and Engineers 78 (1944) 355-358.
//   [P02]  D. M. Potts, L. Zdravkovic, "Finite Element Analysis in Geotechnical Engineering:
//          Application", Thomas Telford (2001), ch. 3 (initial stresses).
//   [TG70] S. P. Timoshenko, J. N. Goodier, "Theory of Elasticity", 3rd ed., McGraw-Hill (1970).
#pragma once

#include <algorithm>
#include <cmath>
#include <string>

#include "core/types.hpp"
#include "fem/explicit_mesh.hpp"
#include "fem/explicit_solid.hpp"
#include "fem/settings.hpp"
#include "materials/strength/stress_tensor.hpp"
#include "parts/setup.hpp"

namespace crater::fem {

/// The geostatic state's constants, resolved from the settings, the domain's gravity and the
/// material.
struct GeostaticParams {
  int vertical_axis = 0;   // the axis gravity acts along (0, 1 or 2)
  Real gravity_m_s2 = 0;   // gravity's component on it, signed [m/s^2] (-9.81: down is -axis)
  Real surface_m = 0;      // the free surface's coordinate on vertical_axis [m]
  Real density_kg_m3 = 0;  // \rho_0 [kg/m^3]
  Real k0 = 0;             // K_0 [-]
};

/// K_0 of an elastic layer in uniaxial strain: \nu / (1 - \nu) [-].
inline Real at_rest_earth_pressure_coefficient(Real poisson_ratio) {
  return poisson_ratio / (Real(1) - poisson_ratio);
}

/// The geostatic stress [Pa] at coordinate `coordinate_m` on the vertical axis: \sigma_v =
/// -\rho_0 |g| d there, K_0 \sigma_v on the other diagonal entries, d the depth below the
/// surface (zero stress above it).
inline materials::Mat3 geostatic_stress(const GeostaticParams& p, Real coordinate_m) {
  const Real down = p.gravity_m_s2 < 0 ? Real(-1) : Real(1);
  const Real depth_m = std::max(Real(0), (coordinate_m - p.surface_m) * down);
  const Real sigma_v = -p.density_kg_m3 * std::abs(p.gravity_m_s2) * depth_m;
  materials::Mat3 s = (p.k0 * sigma_v) * materials::Mat3::Identity();
  s(p.vertical_axis, p.vertical_axis) = sigma_v;
  return s;
}

/// The constants of `settings` for a part of `dimension` in gravity `gravity_m_s2` (its first
/// `dimension` components along exactly one axis, or std::invalid_argument: the scenario
/// reader rejects the others) of `material` (K_0 unset: \nu / (1 - \nu) of its elastic
/// constants).
GeostaticParams geostatic_params(const GeostaticSettings& settings, int dimension,
                                 const parts::Vec3& gravity_m_s2, const SolidMaterial& material);

/// What setting the state found.
struct GeostaticReport {
  Index outside_yield = 0;   // elements whose state the law's first return would change
  Index first_outside = -1;  // the lowest-numbered of them, or -1
};

/// Sets every element's stress to geostatic_stress at its integration point (the mean of its
/// reference node positions) and counts the elements whose state lies outside the material's
/// yield surface (a zero strain increment through the law gives plastic strain).
template <int D>
GeostaticReport initialise_geostatic_stress(ExplicitMesh<D>& mesh, const SolidMaterial& material,
                                            const GeostaticParams& p);

/// initialise_geostatic_stress with geostatic_params, and a warning naming part `part_name`
/// when some elements start outside the yield surface.
template <int D>
void apply_geostatic_stress(ExplicitMesh<D>& mesh, const SolidMaterial& material,
                            const GeostaticSettings& settings, const parts::Vec3& gravity_m_s2,
                            const std::string& part_name);

}  // namespace crater::fem
