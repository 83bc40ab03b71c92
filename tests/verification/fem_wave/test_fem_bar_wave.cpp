// Verification: an elastic compression wave in a long steel bar under 1D strain, integrated by
// central differences with the FEM kernels (plane-strain Q4 and Hex8).
//
// Reference (computed by nobody here): in 1D strain a step in end velocity v_0 travels at the
// dilatational speed c_d = \sqrt{(\lambda + 2\mu)/\rho} and leaves behind it the particle
// velocity v_0 and the stress \sigma_{xx} = -\rho c_d v_0 (the elastic impedance relation;
// Kolsky, "Stress Waves in Solids", 1953, ch. 2; Graff, "Wave Motion in Elastic Solids", 1975,
// §1.1). Steel: E = 200 GPa, \nu = 0.3, \rho = 7850 kg/m^3: c_d = 5856.4 m/s.
//
// Set-up: bar 1 m long, 2 mm elements, every lateral velocity component held at zero (1D
// strain), v_x = v_0 = 1 m/s imposed at x = 0 from t = 0; time step half the stable step; bulk
// viscosity and hourglass control at their defaults. The front is the point where v_x crosses
// v_0/2, found by linear interpolation scanning from the far end (dispersive ringing trails the
// front); its speed is measured between the times it has run 0.3 m and 0.8 m, which removes
// the start-up transient.
// Tolerances: front speed within 1 % of c_d (the brief); the plateau stress, averaged over
// 0.1 m < x < 0.2 m at the last time, within 1 % of \rho c_d v_0.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "../fem_support/central_difference.hpp"
#include "fem/explicit_solid.hpp"

namespace crater::fem {
namespace {

constexpr Real kLength = 1.0;
constexpr Real kElement = 2e-3;
constexpr Real kDensity = 7850.0;
constexpr Real kImpact = 1.0;

/// x of the first crossing of v_x = v_0/2 seen from the far end, along the nodes at y = z = 0.
template <int D>
Real front_position(const ExplicitMesh<D>& mesh, Index cells_along) {
  for (Index i = cells_along; i > 0; --i) {
    const Real v_right = mesh.velocity[static_cast<std::size_t>(i)].x();
    const Real v_left = mesh.velocity[static_cast<std::size_t>(i - 1)].x();
    if (v_left >= 0.5 * kImpact && v_right < 0.5 * kImpact) {
      const Real x_left = mesh.reference_position[static_cast<std::size_t>(i - 1)].x();
      return x_left + kElement * (v_left - 0.5 * kImpact) / (v_left - v_right);
    }
  }
  return 0;
}

template <int D>
void run_bar() {
  StructuredMeshSpec<D> spec;
  spec.lo = Vec<D>::Zero();
  spec.hi = Vec<D>::Constant(kElement);
  spec.hi.x() = kLength;
  spec.cells.fill(1);
  spec.cells[0] = static_cast<Index>(std::llround(kLength / kElement));
  ExplicitMesh<D> mesh = structured_mesh<D>(spec);
  SolidMaterial material;
  material.strength = materials::steel_elastic();
  material.density_kg_m3 = kDensity;
  initialise<D>(mesh, material);

  std::vector<testing::PrescribedVelocity> prescribed;
  for (Index n = 0; n < mesh.node_count(); ++n) {
    for (int k = 1; k < D; ++k)
      prescribed.push_back({.node = n, .axis = k, .value = 0});
    if (mesh.reference_position[static_cast<std::size_t>(n)].x() == 0)
      prescribed.push_back({.node = n, .axis = 0, .value = kImpact});
  }
  testing::CentralDifference<D> loop(mesh, material, prescribed);

  const Real c_d = materials::dilatational_wave_speed(materials::steel_elastic(), kDensity);
  const Real dt = 0.5 * stable_time_step<D>(mesh, material);
  const Real t1 = 0.3 / c_d, t2 = 0.8 / c_d;
  Real x1 = -1, x2 = -1, time1 = 0, time2 = 0;
  while (loop.time_s() < t2) {
    const ForceReport report = loop.step(dt);
    ASSERT_EQ(report.inverted_element, -1);
    if (x1 < 0 && loop.time_s() >= t1) {
      x1 = front_position<D>(mesh, spec.cells[0]);
      time1 = loop.time_s();
    }
  }
  x2 = front_position<D>(mesh, spec.cells[0]);
  time2 = loop.time_s();
  const Real speed = (x2 - x1) / (time2 - time1);

  Real stress = 0;
  int count = 0;
  for (Index e = 0; e < mesh.element_count(); ++e) {
    const Real x = mesh.element_positions(e)[0].x();
    if (x > 0.1 && x < 0.2) {
      stress += mesh.stress[static_cast<std::size_t>(e)](0, 0);
      ++count;
    }
  }
  stress /= count;
  const Real impedance_stress = -kDensity * c_d * kImpact;
  std::printf(
      "bar wave D=%d: front speed %.2f m/s vs c_d %.2f m/s (%.3f %%); plateau stress "
      "%.4f MPa vs %.4f MPa (%.3f %%)\n",
      D, speed, c_d, 100 * (speed / c_d - 1), stress / 1e6, impedance_stress / 1e6,
      100 * (stress / impedance_stress - 1));
  EXPECT_NEAR(speed, c_d, 0.01 * c_d);
  EXPECT_NEAR(stress, impedance_stress, 0.01 * std::abs(impedance_stress));
}

TEST(FemBarWave, PlaneStrainQ4FrontAtDilatationalSpeed) {
  run_bar<2>();
}

TEST(FemBarWave, Hex8FrontAtDilatationalSpeed) {
  run_bar<3>();
}

}  // namespace
}  // namespace crater::fem
