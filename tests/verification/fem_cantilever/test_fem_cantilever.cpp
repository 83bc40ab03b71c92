// Verification: free vibration of a clamped steel cantilever in plane strain (Q4, one-point
// integration, Flanagan-Belytschko hourglass control), integrated by central differences.
//
// Reference (computed by nobody here): Euler-Bernoulli first bending frequency of a cantilever
// (Timoshenko, Young & Weaver, "Vibration Problems in Engineering", 4th ed. 1974, §5.3):
//   f_1 = (\beta_1 L)^2 / (2\pi L^2) \sqrt{E' I / (\rho A)},   \beta_1 L = 1.875104,
// per metre of depth in plane strain: E' = E/(1 - \nu^2), I/A = H^2/12. L = 1 m, H = 0.05 m
// (slender: L/H = 20, shear and rotary inertia lower f_1 by ~0.3 %), steel E = 200 GPa,
// \nu = 0.3, \rho = 7850 kg/m^3: f_1 = 42.74 Hz.
//
// Set-up: 40 x 8 elements (25 x 6.25 mm); the nodes at x = 0 fixed; initial velocity
// v_y = v_tip \phi_1(x) in the Euler-Bernoulli mode shape, v_tip = 0.01 m/s (small strain);
// step 0.9 x the stable step; 1.6 periods. The period is twice the mean spacing of the zero
// crossings of the tip's mid-height deflection. Each hourglass form (viscous 0.1; stiffness
// 0.05, as LS-DYNA recommends for structures) is run.
// Why 8 elements through the thickness: a one-point element carries only the mean strain, so
// n layers miss ~1/n^2 of the bending energy and f_1 comes out ~1/(2 n^2) low: with 4 layers
// (80 x 4) this gave -3.3 % (viscous) and -2.7 % (stiffness); 80 x 8 gave -0.9 % and -0.6 %,
// 40 x 8 gives -0.9 % and -0.3 %.
// Tolerances (the brief): f_1 within 3 %; hourglass energy below 10 % of the largest internal
// energy (the viscous form's energy is dissipated, so its whole accumulated value counts).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "../fem_support/central_difference.hpp"
#include "fem/explicit_solid.hpp"

namespace crater::fem {
namespace {

constexpr Real kPi = std::numbers::pi;
constexpr Real kLength = 1.0;
constexpr Real kHeight = 0.05;
constexpr Real kDensity = 7850.0;
constexpr Index kCellsAlong = 40;
constexpr Index kCellsThrough = 8;

/// Euler-Bernoulli first cantilever mode shape, 0 at the clamp, 2 at the free end.
Real mode_shape(Real x) {
  const Real beta = 1.875104068711961 / kLength;
  const Real s = (std::cosh(beta * kLength) + std::cos(beta * kLength)) /
                 (std::sinh(beta * kLength) + std::sin(beta * kLength));
  return std::cosh(beta * x) - std::cos(beta * x) - s * (std::sinh(beta * x) - std::sin(beta * x));
}

struct Vibration {
  Real frequency_hz = 0;
  Real max_internal_energy_j = 0;
  Real max_hourglass_energy_j = 0;
};

Vibration vibrate(const HourglassParams& hourglass, Real expected_frequency) {
  StructuredMeshSpec<2> spec;
  spec.lo = Vec<2>(0, -kHeight / 2);
  spec.hi = Vec<2>(kLength, kHeight / 2);
  spec.cells = {kCellsAlong, kCellsThrough};
  ExplicitMesh<2> mesh = structured_mesh<2>(spec);
  SolidMaterial material;
  material.strength = materials::steel_elastic();
  material.density_kg_m3 = kDensity;
  material.hourglass = hourglass;
  initialise<2>(mesh, material);

  const Real tip_scale = 0.01 / mode_shape(kLength);
  std::vector<testing::PrescribedVelocity> clamp;
  for (Index n = 0; n < mesh.node_count(); ++n) {
    const Real x = mesh.reference_position[static_cast<std::size_t>(n)].x();
    mesh.velocity[static_cast<std::size_t>(n)].y() = tip_scale * mode_shape(x);
    if (x == 0) {
      clamp.push_back({.node = n, .axis = 0, .value = 0});
      clamp.push_back({.node = n, .axis = 1, .value = 0});
    }
  }
  testing::CentralDifference<2> loop(mesh, material, clamp);
  const Index tip = structured_node_index<2>(spec.cells, {kCellsAlong, kCellsThrough / 2});
  const Real dt = 0.9 * stable_time_step<2>(mesh, material);
  const Real end = 1.6 / expected_frequency;

  Vibration out;
  std::vector<Real> crossings;
  Real previous = 0;
  while (loop.time_s() < end) {
    const ForceReport report = loop.step(dt);
    EXPECT_EQ(report.inverted_element, -1);
    const Real deflection = mesh.position[static_cast<std::size_t>(tip)].y() -
                            mesh.reference_position[static_cast<std::size_t>(tip)].y();
    if (previous > 0 && deflection <= 0)
      crossings.push_back(loop.time_s() - dt * deflection / (deflection - previous));
    if (previous < 0 && deflection >= 0)
      crossings.push_back(loop.time_s() - dt * deflection / (deflection - previous));
    previous = deflection;
    out.max_internal_energy_j = std::max(out.max_internal_energy_j, loop.internal_energy_j());
    out.max_hourglass_energy_j =
        std::max(out.max_hourglass_energy_j, std::abs(loop.hourglass_energy_j()));
  }
  EXPECT_GE(crossings.size(), 3u);
  if (crossings.size() >= 2) {
    const Real half_period =
        (crossings.back() - crossings.front()) / static_cast<Real>(crossings.size() - 1);
    out.frequency_hz = 1 / (2 * half_period);
  }
  return out;
}

Real euler_bernoulli_frequency() {
  const materials::ElasticParams steel = materials::steel_elastic();
  const Real e_plane = steel.youngs_modulus_pa / (1 - steel.poisson_ratio * steel.poisson_ratio);
  const Real beta_l = 1.875104068711961;
  return beta_l * beta_l / (2 * kPi * kLength * kLength) *
         std::sqrt(e_plane * kHeight * kHeight / 12 / kDensity);
}

void expect_vibration(const HourglassParams& hourglass, const char* label) {
  const Real f_eb = euler_bernoulli_frequency();
  const Vibration v = vibrate(hourglass, f_eb);
  const Real ratio = v.max_hourglass_energy_j / v.max_internal_energy_j;
  std::printf(
      "cantilever, %s hourglass: f_1 = %.3f Hz vs Euler-Bernoulli %.3f Hz (%.2f %%); "
      "hourglass / internal energy = %.2f %%\n",
      label, v.frequency_hz, f_eb, 100 * (v.frequency_hz / f_eb - 1), 100 * ratio);
  EXPECT_NEAR(v.frequency_hz, f_eb, 0.03 * f_eb);
  EXPECT_LT(ratio, 0.10);
}

TEST(FemCantilever, FirstBendingFrequencyStiffnessHourglass) {
  expect_vibration(HourglassParams{.form = HourglassForm::kStiffness, .coefficient = 0.05},
                   "stiffness 0.05");
}

TEST(FemCantilever, FirstBendingFrequencyViscousHourglass) {
  expect_vibration(HourglassParams{.form = HourglassForm::kViscous, .coefficient = 0.1},
                   "viscous 0.1");
}

}  // namespace
}  // namespace crater::fem
