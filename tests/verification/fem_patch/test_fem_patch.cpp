// Verification: the patch test of the one-point Q4 (plane strain) and Hex8 elements with
// Flanagan-Belytschko hourglass control (src/fem/), on distorted meshes.
//
// Reference (computed by nobody here): a constant-strain state is an exact solution of the
// continuum, so a consistent element must reproduce it on any mesh (B. M. Irons, A. Razzaque,
// "Experience with the patch test for convergence of finite elements", in The Mathematical
// Foundations of the FEM, Academic Press 1972; T. Belytschko, W. K. Liu, B. Moran, "Nonlinear
// Finite Elements", Wiley 2000, §8.5): with every node moved by the same linear field
// u = A X, each element's strain increment is exactly sym(L) with L = A (I + A)^{-1} (the
// velocity gradient on the moved configuration), its stress is C : that strain, and the
// internal force at every interior node vanishes. The interior-force identity fails on a
// distorted mesh if the hourglass vectors are not orthogonalised against the linear field
// ([FB81]) or if the gradients are not the uniform-strain ones.
//
// Tolerances: 1e-10 relative on strain and stress (the brief); interior nodal forces below
// 1e-10 of the force scale |sigma| h^{D-1} of one element face.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "fem/explicit_solid.hpp"
#include "fem/kinematics.hpp"

namespace crater::fem {
namespace {

template <int D>
Eigen::Matrix<Real, D, D> strain_field() {
  // A general (non-symmetric) displacement gradient of size ~1e-3: stretch, shear and a
  // small rotation.
  Eigen::Matrix<Real, 3, 3> a;
  a << 1.0e-3, 0.4e-3, -0.3e-3,  //
      -0.2e-3, -0.6e-3, 0.5e-3,  //
      0.1e-3, 0.7e-3, 0.8e-3;
  return a.template topLeftCorner<D, D>();
}

template <int D>
void run_patch_test(HourglassForm form) {
  StructuredMeshSpec<D> spec;
  spec.lo = Vec<D>::Zero();
  spec.hi = Vec<D>::Constant(0.04);
  spec.cells.fill(D == 2 ? 5 : 4);
  spec.distortion = 0.2;
  spec.seed = 7;
  ExplicitMesh<D> mesh = structured_mesh<D>(spec);
  const materials::ElasticParams steel = materials::steel_elastic();
  SolidMaterial material;
  material.strength = steel;
  material.density_kg_m3 = 7850;
  material.hourglass = HourglassParams{.form = form, .coefficient = 0.1};
  initialise<D>(mesh, material);

  // One step of length dt carrying every node by u = A X (velocity A X / dt).
  const Eigen::Matrix<Real, D, D> a = strain_field<D>();
  const Real dt = 1e-7;
  for (Index n = 0; n < mesh.node_count(); ++n) {
    const std::size_t i = static_cast<std::size_t>(n);
    mesh.velocity[i] = a * mesh.reference_position[i] / dt;
    mesh.position[i] = mesh.reference_position[i] + dt * mesh.velocity[i];
  }
  const ForceReport report = compute_internal_forces<D>(mesh, material, dt);
  ASSERT_EQ(report.inverted_element, -1);

  // Exact strain increment and stress (zero initial stress: the rotation does nothing).
  const Eigen::Matrix<Real, D, D> l =
      a * (Eigen::Matrix<Real, D, D>::Identity() + a).inverse() / dt;
  materials::Mat3 l3 = materials::Mat3::Zero();
  l3.template topLeftCorner<D, D>() = l;
  const materials::Mat3 strain = rate_of_deformation(l3) * dt;
  const materials::Mat3 stress = materials::elastic_stress_increment(steel, strain);

  Real worst_strain = 0, worst_stress = 0;
  for (Index e = 0; e < mesh.element_count(); ++e) {
    const NodeArray<D> x = mesh.element_positions(e);
    const UniformStrainGradients<D> g = uniform_strain_gradients<D>(x);
    const materials::Mat3 element_strain =
        rate_of_deformation(velocity_gradient<D>(mesh.element_velocities(e), g)) * dt;
    worst_strain = std::max(worst_strain, (element_strain - strain).norm() / strain.norm());
    worst_stress = std::max(
        worst_stress, (mesh.stress[static_cast<std::size_t>(e)] - stress).norm() / stress.norm());
  }
  EXPECT_LT(worst_strain, 1e-10);
  EXPECT_LT(worst_stress, 1e-10);

  const Real h = 0.04 / spec.cells[0];
  const Real force_scale = stress.norm() * std::pow(h, D - 1);
  Real worst_force = 0;
  Index interior = 0;
  for (Index n = 0; n < mesh.node_count(); ++n) {
    const Vec<D>& x0 = mesh.reference_position[static_cast<std::size_t>(n)];
    bool on_boundary = false;
    for (int k = 0; k < D; ++k)
      on_boundary = on_boundary || x0[k] < 1e-12 || x0[k] > 0.04 - 1e-12;
    if (on_boundary) continue;
    ++interior;
    worst_force = std::max(worst_force,
                           mesh.internal_force[static_cast<std::size_t>(n)].norm() / force_scale);
  }
  EXPECT_GT(interior, 0);
  EXPECT_LT(worst_force, 1e-10);
  std::printf("patch test D=%d %s: max rel. error strain %.2e, stress %.2e, interior force %.2e\n",
              D, form == HourglassForm::kViscous ? "viscous" : "stiffness", worst_strain,
              worst_stress, worst_force);
}

TEST(FemPatch, Q4DistortedMeshViscousHourglass) {
  run_patch_test<2>(HourglassForm::kViscous);
}

TEST(FemPatch, Q4DistortedMeshStiffnessHourglass) {
  run_patch_test<2>(HourglassForm::kStiffness);
}

TEST(FemPatch, Hex8DistortedMeshViscousHourglass) {
  run_patch_test<3>(HourglassForm::kViscous);
}

TEST(FemPatch, Hex8DistortedMeshStiffnessHourglass) {
  run_patch_test<3>(HourglassForm::kStiffness);
}

}  // namespace
}  // namespace crater::fem
