// Unit tests of the initial geostatic stress (src/fem/geostatic.hpp): the stress against
// \sigma_v = -\rho g d, \sigma_h = K_0 \sigma_v written out by hand; the resolution of gravity's
// axis and of the default K_0 = \nu/(1 - \nu); exact nodal equilibrium of the state with the
// lumped weights on a mesh of boxes in layers of unequal heights (2D and 3D); and the yield
// check of a cohesionless Drucker-Prager soil, whose compression cone admits K_0 down to the
// Rankine active coefficient (1 - \sin\phi)/(1 + \sin\phi) and no further.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "core/index.hpp"
#include "fem/explicit_mesh.hpp"
#include "fem/explicit_solid.hpp"
#include "fem/geostatic.hpp"
#include "materials/strength/strength.hpp"

namespace crater::fem {
namespace {

constexpr Real kRho = 1800;  // kg/m^3
constexpr Real kG = 9.81;    // m/s^2

TEST(FemGeostatic, StressIsRhoGDepthWithK0Sideways) {
  const GeostaticParams p{
      .vertical_axis = 1, .gravity_m_s2 = -kG, .surface_m = 2.0, .density_kg_m3 = kRho, .k0 = 0.5};
  const materials::Mat3 s = geostatic_stress(p, -1.0);  // 3 m deep
  const Real sigma_v = -1800.0 * 9.81 * 3.0;
  EXPECT_DOUBLE_EQ(s(1, 1), sigma_v);
  EXPECT_DOUBLE_EQ(s(0, 0), 0.5 * sigma_v);
  EXPECT_DOUBLE_EQ(s(2, 2), 0.5 * sigma_v);  // 2D: the plane-strain z is horizontal too
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (i != j) {
        EXPECT_EQ(s(i, j), 0);
      }
  EXPECT_TRUE(geostatic_stress(p, 2.5).isZero());  // above the surface
  EXPECT_TRUE(geostatic_stress(p, 2.0).isZero());  // at it
  // Gravity along +z: down is +z, depth = z - surface.
  const GeostaticParams q{
      .vertical_axis = 2, .gravity_m_s2 = kG, .surface_m = 1.0, .density_kg_m3 = kRho, .k0 = 2.0};
  const materials::Mat3 t = geostatic_stress(q, 4.0);
  EXPECT_DOUBLE_EQ(t(2, 2), -1800.0 * 9.81 * 3.0);
  EXPECT_DOUBLE_EQ(t(0, 0), 2.0 * t(2, 2));
  EXPECT_TRUE(geostatic_stress(q, 0.0).isZero());
}

SolidMaterial soil(Real poisson_ratio = 0.3) {
  SolidMaterial m;
  m.strength = materials::ElasticParams{.youngs_modulus_pa = 80e6, .poisson_ratio = poisson_ratio};
  m.density_kg_m3 = kRho;
  return m;
}

TEST(FemGeostatic, ParamsFindGravitysAxisAndTheElasticK0) {
  GeostaticSettings s{.surface_m = 1.5, .k0 = std::nullopt};
  const GeostaticParams p = geostatic_params(s, 3, {0, 0, -kG}, soil(0.25));
  EXPECT_EQ(p.vertical_axis, 2);
  EXPECT_EQ(p.gravity_m_s2, -kG);
  EXPECT_EQ(p.surface_m, 1.5);
  EXPECT_EQ(p.density_kg_m3, kRho);
  EXPECT_DOUBLE_EQ(p.k0, 0.25 / 0.75);
  s.k0 = 0.7;
  EXPECT_EQ(geostatic_params(s, 2, {0, -kG, 0}, soil()).k0, 0.7);
  EXPECT_EQ(geostatic_params(s, 2, {0, -kG, 0}, soil()).vertical_axis, 1);
  EXPECT_THROW(geostatic_params(s, 2, {0, 0, 0}, soil()), std::invalid_argument);
  EXPECT_THROW(geostatic_params(s, 3, {1, -kG, 0}, soil()), std::invalid_argument);
  SolidMaterial hjc = soil();
  hjc.strength = materials::HolmquistJohnsonCookLaw{};
  EXPECT_THROW(geostatic_params(s, 3, {0, -kG, 0}, hjc), std::invalid_argument);
}

/// A column of boxes along gravity's axis (y, index 1), its layers of unequal heights (the
/// structured mesh's y coordinates remapped by y^1.5: still boxes), in the geostatic state with
/// the surface at its top. Every node off the base carries its weight exactly: the vertical
/// internal force plus m g is zero to rounding, and the horizontal one vanishes away from the
/// sides (where rollers would take it).
template <int D>
void expect_nodal_equilibrium() {
  StructuredMeshSpec<D> spec;
  spec.hi = Vec<D>::Ones();
  spec.hi[1] = 4;
  spec.cells.fill(3);
  spec.cells[1] = 8;
  ExplicitMesh<D> mesh = structured_mesh<D>(spec);
  for (auto& x : mesh.position)
    x[1] = 4 * std::pow(x[1] / 4, 1.5);
  mesh.reference_position = mesh.position;
  const SolidMaterial material = soil();
  initialise<D>(mesh, material);
  const GeostaticReport r = initialise_geostatic_stress<D>(mesh, material,
                                                           GeostaticParams{.vertical_axis = 1,
                                                                           .gravity_m_s2 = -kG,
                                                                           .surface_m = 4,
                                                                           .density_kg_m3 = kRho,
                                                                           .k0 = 0.6});
  EXPECT_EQ(r.outside_yield, 0);  // elastic: no yield surface
  compute_internal_forces<D>(mesh, material, 0);
  Real largest_weight = 0;
  for (Real m : mesh.mass)
    largest_weight = std::max(largest_weight, m * kG);
  for (Index n = 0; n < mesh.node_count(); ++n) {
    const Vec<D>& x = mesh.reference_position[at(n)];
    const Vec<D>& f = mesh.internal_force[at(n)];
    if (x[1] == 0) continue;  // the base: its support takes the load
    EXPECT_NEAR(f[1] - mesh.mass[at(n)] * kG, 0, 1e-12 * largest_weight) << "node " << n;
    for (int k = 0; k < D; ++k) {
      const bool side = x[k] == 0 || x[k] == 1;
      if (k != 1 && !side) {
        EXPECT_NEAR(f[k], 0, 1e-12 * largest_weight) << "node " << n;
      }
    }
  }
}

TEST(FemGeostatic, StateIsInNodalEquilibriumOnLayersOfBoxes) {
  expect_nodal_equilibrium<2>();
  expect_nodal_equilibrium<3>();
}

/// Elements below the surface outside a cohesionless Drucker-Prager cone (compression fit,
/// \phi = 30 deg): none for K_0 just above K_a = (1 - \sin\phi)/(1 + \sin\phi) = 1/3, every
/// one for K_0 just below.
TEST(FemGeostatic, DruckerPragerAdmitsK0DownToTheActiveLimit) {
  const Real phi = 30 * std::numbers::pi / 180;
  const Real k_active = (1 - std::sin(phi)) / (1 + std::sin(phi));
  SolidMaterial material = soil();
  material.strength = materials::drucker_prager_from_mohr_coulomb(
      materials::ElasticParams{.youngs_modulus_pa = 80e6, .poisson_ratio = 0.3}, 0, phi, phi,
      materials::MohrCoulombFit::kCompressionCone);
  StructuredMeshSpec<3> spec;
  spec.hi = Vec<3>(1, 1, 4);
  spec.cells = {2, 2, 8};
  ExplicitMesh<3> mesh = structured_mesh<3>(spec);
  initialise<3>(mesh, material);
  auto outside = [&](Real k0) {
    return initialise_geostatic_stress<3>(mesh, material,
                                          GeostaticParams{.vertical_axis = 2,
                                                          .gravity_m_s2 = -kG,
                                                          .surface_m = 4,
                                                          .density_kg_m3 = kRho,
                                                          .k0 = k0});
  };
  EXPECT_EQ(outside(k_active * (1 + 1e-6)).outside_yield, 0);
  EXPECT_EQ(outside(1 - std::sin(phi)).outside_yield, 0);  // Jaky
  const GeostaticReport below = outside(k_active * (1 - 1e-6));
  EXPECT_EQ(below.outside_yield, mesh.element_count());
  EXPECT_EQ(below.first_outside, 0);
  // The state is what was asked for, whatever the yield check found.
  EXPECT_DOUBLE_EQ(mesh.stress[0](2, 2), -kRho * kG * 3.75);
  EXPECT_DOUBLE_EQ(mesh.stress[0](0, 0), k_active * (1 - 1e-6) * mesh.stress[0](2, 2));
}

}  // namespace
}  // namespace crater::fem
