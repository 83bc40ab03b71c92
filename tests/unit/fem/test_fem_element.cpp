// Unit tests of the one-point explicit elements (src/fem/): uniform strain gradients against
// exact Gauss quadrature of the trilinear/bilinear map, linear completeness, orthogonal hourglass
// vectors, the stable-step bound against the element's computed eigenvalues, the Jaumann
// rotation, hourglass and bulk-viscosity forces, the structured mesh and lumped masses.
// Tolerances are round-off level (1e-12 relative) unless a comment says otherwise.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>

#include <Eigen/Eigenvalues>

#include "fem/bulk_viscosity.hpp"
#include "fem/element_geometry.hpp"
#include "fem/explicit_mesh.hpp"
#include "fem/explicit_solid.hpp"
#include "fem/hourglass.hpp"
#include "fem/kinematics.hpp"
#include "parallel/parallel.hpp"

namespace crater::fem {
namespace {

constexpr Real kRoundoff = 1e-12;

/// A distorted element: the reference cube/square [0, h]^D with every node moved by a fixed,
/// non-symmetric offset of up to 20 % of h.
template <int D>
NodeArray<D> distorted_element(Real h) {
  constexpr Real kOffsets[8][3] = {{0.03, -0.05, 0.02},  {0.11, 0.04, -0.07}, {-0.06, 0.09, 0.05},
                                   {0.08, -0.12, 0.01},  {-0.04, 0.02, 0.13}, {0.07, 0.06, -0.09},
                                   {-0.10, -0.03, 0.04}, {0.05, 0.12, -0.02}};
  NodeArray<D> x;
  for (int node = 0; node < kElementNodes<D>; ++node)
    for (int k = 0; k < D; ++k)
      x[node][k] =
          h * (Real(0.5) * (reference_sign<D>(node, k) + 1) + Real(0.2) * kOffsets[node][k]);
  return x;
}

/// Exact \int_V N_{I,i} dV and V by 2-point Gauss quadrature per axis of the isoparametric map
/// (the integrands are polynomials of degree <= 2 per reference coordinate, so this is exact).
template <int D>
UniformStrainGradients<D> gauss_gradients(const NodeArray<D>& x) {
  const Real gp = Real(1) / std::sqrt(Real(3));
  UniformStrainGradients<D> out;
  for (auto& b : out.b)
    b.setZero();
  const int points = D == 2 ? 4 : 8;
  for (int q = 0; q < points; ++q) {
    Vec<D> xi;
    for (int k = 0; k < D; ++k)
      xi[k] = ((q >> k) & 1) ? gp : -gp;
    // dN_I / dxi_k for the (bi/tri)linear shape functions N_I = prod_k (1 + xi_k s_Ik) / 2.
    std::array<Vec<D>, kElementNodes<D>> dn;
    for (int node = 0; node < kElementNodes<D>; ++node)
      for (int k = 0; k < D; ++k) {
        Real value = reference_sign<D>(node, k) / Real(2);
        for (int m = 0; m < D; ++m)
          if (m != k) value *= (Real(1) + xi[m] * reference_sign<D>(node, m)) / Real(2);
        dn[node][k] = value;
      }
    Eigen::Matrix<Real, D, D> jac = Eigen::Matrix<Real, D, D>::Zero();  // dx_i / dxi_k
    for (int node = 0; node < kElementNodes<D>; ++node)
      jac += x[node] * dn[node].transpose();
    const Real det = jac.determinant();
    const Eigen::Matrix<Real, D, D> inv = jac.inverse();
    out.volume += det;
    for (int node = 0; node < kElementNodes<D>; ++node)
      out.b[node] += det * (inv.transpose() * dn[node]);
  }
  for (auto& b : out.b)
    b /= out.volume;
  return out;
}

template <int D>
void expect_gradients_match_quadrature() {
  const NodeArray<D> x = distorted_element<D>(0.7);
  const UniformStrainGradients<D> g = uniform_strain_gradients<D>(x);
  const UniformStrainGradients<D> ref = gauss_gradients<D>(x);
  EXPECT_NEAR(g.volume, ref.volume, kRoundoff * ref.volume);
  for (int node = 0; node < kElementNodes<D>; ++node)
    for (int k = 0; k < D; ++k)
      EXPECT_NEAR(g.b[node][k], ref.b[node][k], kRoundoff / 0.7)
          << "node " << node << " axis " << k;
}

TEST(FemElement, Q4GradientsEqualExactQuadrature) {
  expect_gradients_match_quadrature<2>();
}

TEST(FemElement, Hex8GradientsEqualExactQuadrature) {
  expect_gradients_match_quadrature<3>();
}

template <int D>
void expect_linear_completeness_and_orthogonal_hourglass() {
  const NodeArray<D> x = distorted_element<D>(1.3);
  const UniformStrainGradients<D> g = uniform_strain_gradients<D>(x);
  Eigen::Matrix<Real, D, D> xb = Eigen::Matrix<Real, D, D>::Zero();
  Vec<D> sum_b = Vec<D>::Zero();
  for (int node = 0; node < kElementNodes<D>; ++node) {
    xb += x[node] * g.b[node].transpose();
    sum_b += g.b[node];
  }
  EXPECT_LT((xb - Eigen::Matrix<Real, D, D>::Identity()).norm(), kRoundoff);
  EXPECT_LT(sum_b.norm(), kRoundoff);
  const HourglassVectors<D> gamma = hourglass_shape_vectors<D>(x, g);
  for (int a = 0; a < kHourglassModes<D>; ++a) {
    Real ones = 0;
    Vec<D> lin = Vec<D>::Zero();
    for (int node = 0; node < kElementNodes<D>; ++node) {
      ones += gamma(a, node);
      lin += gamma(a, node) * x[node];
    }
    EXPECT_NEAR(ones, 0, kRoundoff);
    EXPECT_LT(lin.norm(), kRoundoff * 1.3);
  }
}

TEST(FemElement, Q4LinearCompletenessAndOrthogonalHourglass) {
  expect_linear_completeness_and_orthogonal_hourglass<2>();
}

TEST(FemElement, Hex8LinearCompletenessAndOrthogonalHourglass) {
  expect_linear_completeness_and_orthogonal_hourglass<3>();
}

TEST(FemElement, CharacteristicLengthOfSquareAndCube) {
  // Closed forms from the bound (element_geometry.hpp): h / sqrt(2) and h / sqrt(3).
  NodeArray<2> sq;
  NodeArray<3> cube;
  for (int node = 0; node < 8; ++node) {
    if (node < 4)
      for (int k = 0; k < 2; ++k)
        sq[node][k] = 0.5 * 0.01 * (reference_sign<2>(node, k) + 1);
    for (int k = 0; k < 3; ++k)
      cube[node][k] = 0.5 * 0.01 * (reference_sign<3>(node, k) + 1);
  }
  EXPECT_NEAR(characteristic_length<2>(uniform_strain_gradients<2>(sq)), 0.01 / std::sqrt(2.0),
              1e-15);
  EXPECT_NEAR(characteristic_length<3>(uniform_strain_gradients<3>(cube)), 0.01 / std::sqrt(3.0),
              1e-15);
}

/// Largest frequency of the free uniform-strain element (no hourglass stiffness), lumped mass,
/// computed from its assembled stiffness V B^T C B. The bound L_e / c_d must not exceed the
/// critical step 2 / omega_max.
template <int D>
void expect_stable_step_is_a_bound(Real nu) {
  const NodeArray<D> x = distorted_element<D>(1.0);
  const UniformStrainGradients<D> g = uniform_strain_gradients<D>(x);
  const Real e_mod = 1.0, rho = 1.0;
  const Real lambda = e_mod * nu / ((1 + nu) * (1 - 2 * nu)), mu = e_mod / (2 * (1 + nu));
  constexpr int n = kElementNodes<D>;
  constexpr int dofs = n * D;
  // Strain operator on the D x D symmetric strain, stored as a full D*D vector.
  Eigen::Matrix<Real, D * D, dofs> bmat = Eigen::Matrix<Real, D * D, dofs>::Zero();
  for (int node = 0; node < n; ++node)
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j) {
        bmat(i * D + j, node * D + i) += 0.5 * g.b[node][j];
        bmat(i * D + j, node * D + j) += 0.5 * g.b[node][i];
      }
  Eigen::Matrix<Real, D * D, D* D> c = Eigen::Matrix<Real, D * D, D * D>::Zero();
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j) {
      c(i * D + j, i * D + j) += 2 * mu;
      c(i * D + i, j * D + j) += lambda;
    }
  const Eigen::Matrix<Real, dofs, dofs> k = g.volume * bmat.transpose() * c * bmat;
  const Real mass = rho * g.volume / n;
  // Dynamic size: a fixed-size solver unrolls for every D and took a minute to compile.
  const Eigen::MatrixXd k_over_m = (k / mass).template cast<double>();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(k_over_m);
  const Real omega_max = std::sqrt(eig.eigenvalues().maxCoeff());
  const Real c_d = std::sqrt((lambda + 2 * mu) / rho);
  const Real dt_bound = characteristic_length<D>(g) / c_d;
  EXPECT_LE(dt_bound, 2 / omega_max * (1 + 1e-12)) << "nu = " << nu;
  // And the bound is not absurdly conservative (within a factor 2 of the true limit).
  EXPECT_GT(dt_bound, 0.5 * 2 / omega_max) << "nu = " << nu;
}

TEST(FemElement, StableStepBoundsTheElementFrequency) {
  for (const Real nu : {0.0, 0.3, 0.45, 0.49}) {
    expect_stable_step_is_a_bound<2>(nu);
    expect_stable_step_is_a_bound<3>(nu);
  }
}

TEST(FemKinematics, JaumannRotationOfARigidSpinIsTheRotation) {
  // A uniaxial stress carried by a body spinning at omega for a time T: the exact answer is
  // R(omega T) sigma R^T. Hughes-Winget rotates by 2 atan(omega dt / 2) per step: error
  // ~ (omega dt)^2 / 12 relative to the angle, 1e-7 at omega dt = 1e-3.
  materials::Mat3 sigma = materials::Mat3::Zero();
  sigma(0, 0) = 100e6;
  const Real omega = 2.0, total = 0.5;
  const int steps = 1000;
  const Real dt = total / steps;
  materials::Mat3 l = materials::Mat3::Zero();  // v = omega e_z x r
  l(0, 1) = -omega;
  l(1, 0) = omega;
  materials::Mat3 s = sigma;
  for (int k = 0; k < steps; ++k)
    s = jaumann_rotate(s, spin(l), dt);
  const Real angle = omega * total;
  materials::Mat3 r = materials::Mat3::Identity();
  r(0, 0) = r(1, 1) = std::cos(angle);
  r(1, 0) = std::sin(angle);
  r(0, 1) = -std::sin(angle);
  const materials::Mat3 exact = r * sigma * r.transpose();
  EXPECT_LT((s - exact).norm(), 1e-6 * sigma.norm());
  // The rotation is orthogonal: the invariants are kept to round-off.
  EXPECT_NEAR(s.trace(), sigma.trace(), 1e-12 * sigma.norm());
  EXPECT_NEAR(s.norm(), sigma.norm(), 1e-12 * sigma.norm());
}

TEST(FemKinematics, PlaneJaumannRotationIsTheGeneralOneForAPlaneSpin) {
  // Random symmetric stresses and in-plane spins over a range of w dt: the written-out plane
  // rotation agrees with the general Hughes-Winget form to round-off.
  std::srand(3);
  for (int k = 0; k < 200; ++k) {
    materials::Mat3 a = materials::Mat3::Random() * 300e6;
    const materials::Mat3 sigma = a + a.transpose();
    materials::Mat3 l = materials::Mat3::Zero();
    l.topLeftCorner<2, 2>() = Eigen::Matrix2d::Random() * std::pow(10.0, k % 7);
    const Real dt = 1e-3;
    const materials::Mat3 general = jaumann_rotate(sigma, spin(l), dt);
    const materials::Mat3 plane = jaumann_rotate_plane(sigma, spin(l)(0, 1), dt);
    EXPECT_LT((plane - general).norm(), 1e-14 * sigma.norm()) << "case " << k;
    EXPECT_EQ(plane(0, 1), plane(1, 0));
  }
}

template <int D>
void expect_hourglass_resists_only_hourglass_modes(HourglassForm form) {
  const NodeArray<D> x = distorted_element<D>(0.01);
  const UniformStrainGradients<D> g = uniform_strain_gradients<D>(x);
  const HourglassVectors<D> gamma = hourglass_shape_vectors<D>(x, g);
  const HourglassParams params{.form = form, .coefficient = 0.1};
  // A linear velocity field (translation + rotation + strain): no hourglass force.
  Eigen::Matrix<Real, D, D> a;
  a.setRandom();
  NodeArray<D> v;
  for (int node = 0; node < kElementNodes<D>; ++node)
    v[node] = Vec<D>::Constant(0.3) + a * x[node];
  HourglassState<D> state = HourglassState<D>::Zero();
  const HourglassForces<D> none =
      hourglass_forces<D>(params, gamma, v, g.volume, 7850, 5800, 1e-6, state);
  for (const Vec<D>& f : none.force)
    EXPECT_LT(f.norm(), 1e-10 * 7850 * 5800 * g.volume / 0.01);
  // The base hourglass pattern along x: forces oppose the motion (positive power).
  const HourglassVectors<D> base = hourglass_base_vectors<D>();
  for (int node = 0; node < kElementNodes<D>; ++node)
    v[node] = Vec<D>::Unit(0) * base(0, node);
  state.setZero();
  const HourglassForces<D> hg =
      hourglass_forces<D>(params, gamma, v, g.volume, 7850, 5800, 1e-6, state);
  Real power = 0;
  for (int node = 0; node < kElementNodes<D>; ++node)
    power -= hg.force[node].dot(v[node]);
  EXPECT_GT(power, 0);
  EXPECT_NEAR(power, hg.power_w, 1e-12 * std::abs(power));
}

TEST(FemHourglass, ResistsOnlyHourglassModes) {
  for (const HourglassForm form : {HourglassForm::kViscous, HourglassForm::kStiffness}) {
    expect_hourglass_resists_only_hourglass_modes<2>(form);
    expect_hourglass_resists_only_hourglass_modes<3>(form);
  }
}

TEST(FemBulkViscosity, OnlyInCompressionAndStepFormula) {
  const BulkViscosityParams p;
  EXPECT_EQ(bulk_viscosity_pressure(p, 7850, 5800, 0.01, 10.0), 0);
  // rho l (1.5 l e^2 + 0.06 c |e|) = 7850 * 0.01 * (1.5 * 0.01 * 100 + 0.06 * 5800 * 10)
  EXPECT_NEAR(bulk_viscosity_pressure(p, 7850, 5800, 0.01, -10.0),
              7850 * 0.01 * (1.5 * 0.01 * 100 + 0.06 * 5800 * 10), 1e-6);
  EXPECT_NEAR(stable_element_step(p, 0.01, 5800, 1.0), 0.01 / 5800, 1e-18);
  EXPECT_LT(stable_element_step(p, 0.01, 5800, -1e4), 0.01 / 5800);
}

template <int D>
void expect_structured_mesh_volume_and_mass() {
  StructuredMeshSpec<D> spec;
  spec.lo = Vec<D>::Constant(-0.5);
  spec.hi = Vec<D>::LinSpaced(1.0, 2.0);
  for (int k = 0; k < D; ++k)
    spec.cells[static_cast<std::size_t>(k)] = 3 + k;
  spec.distortion = 0.2;
  ExplicitMesh<D> mesh = structured_mesh<D>(spec);
  SolidMaterial material;
  material.strength = materials::steel_elastic();
  material.density_kg_m3 = 7850;
  initialise<D>(mesh, material);
  Real box = 1, volume = 0, mass = 0;
  for (int k = 0; k < D; ++k)
    box *= spec.hi[k] - spec.lo[k];
  for (const Real v : mesh.reference_volume)
    volume += v;
  for (const Real m : mesh.mass)
    mass += m;
  // The boundary nodes stay put, so the distorted elements still tile the box exactly.
  EXPECT_NEAR(volume, box, kRoundoff * box);
  EXPECT_NEAR(mass, 7850 * box, kRoundoff * 7850 * box);
  Index expected_nodes = 1;
  for (int k = 0; k < D; ++k)
    expected_nodes *= spec.cells[static_cast<std::size_t>(k)] + 1;
  EXPECT_EQ(mesh.node_count(), expected_nodes);
}

TEST(FemMesh, StructuredMeshTilesTheBoxAndLumpsTheMass) {
  expect_structured_mesh_volume_and_mass<2>();
  expect_structured_mesh_volume_and_mass<3>();
}

/// The element loop and the per-node gather give the same bits for 1 and 2 threads
/// (DESIGN.md §2: results bit-identical for any thread count).
template <int D>
void expect_forces_independent_of_threads() {
  StructuredMeshSpec<D> spec;
  spec.cells.fill(D == 2 ? 60 : 14);  // above the serial threshold: the parallel path runs
  spec.distortion = 0.2;
  ExplicitMesh<D> mesh = structured_mesh<D>(spec);
  SolidMaterial material;
  material.strength = materials::paper_steel_johnson_cook();
  material.density_kg_m3 = 7850;
  initialise<D>(mesh, material);
  for (std::size_t i = 0; i < mesh.velocity.size(); ++i) {
    const Vec<D>& x = mesh.reference_position[i];
    mesh.velocity[i] = Vec<D>::Constant(std::sin(7 * x.sum())) * 50.0;
    mesh.position[i] = x + 1e-5 * mesh.velocity[i];
  }
  const int threads = parallel::max_threads();
  ExplicitMesh<D> one = mesh;
  ExplicitMesh<D> two = mesh;
  parallel::set_threads(1);
  const ForceReport r1 = compute_internal_forces<D>(one, material, 1e-5);
  parallel::set_threads(2);
  const ForceReport r2 = compute_internal_forces<D>(two, material, 1e-5);
  parallel::set_threads(threads);
  EXPECT_EQ(r1.internal_energy_increment_j, r2.internal_energy_increment_j);
  EXPECT_EQ(r1.hourglass_energy_increment_j, r2.hourglass_energy_increment_j);
  EXPECT_EQ(r1.stable_dt_s, r2.stable_dt_s);
  EXPECT_GT(r1.internal_energy_increment_j, 0);
  for (std::size_t i = 0; i < one.internal_force.size(); ++i)
    ASSERT_EQ(one.internal_force[i], two.internal_force[i]) << "node " << i;
}

TEST(FemMesh, InternalForcesAreBitIdenticalForAnyThreadCount) {
  expect_forces_independent_of_threads<2>();
  expect_forces_independent_of_threads<3>();
}

}  // namespace
}  // namespace crater::fem

namespace crater::fem {
namespace {

/// One Q4 whose node 2 is pulled across the opposite diagonal: volume <= 0. With
/// erode_inverted the element erodes (zero stress, no forces); without, the force evaluation
/// reports it (the part stops the run, exit 3, naming it).
ForceReport evaluate_inverted_q4(bool erode_inverted, ExplicitMesh<2>& mesh) {
  StructuredMeshSpec<2> spec;
  spec.cells = {1, 1};
  mesh = structured_mesh<2>(spec);
  SolidMaterial material;
  material.strength = materials::steel_elastic();
  material.density_kg_m3 = 7850;
  material.erode_inverted = erode_inverted;
  initialise<2>(mesh, material);
  mesh.position[3] = Vec<2>(-0.5, -0.5);  // node (1, 1) pulled past node (0, 0)
  return compute_internal_forces<2>(mesh, material, 1e-7);
}

TEST(FemErosion, InvertedElementErodesOnlyWhenAsked) {
  ExplicitMesh<2> mesh;
  const ForceReport off = evaluate_inverted_q4(false, mesh);
  EXPECT_EQ(off.inverted_element, 0);
  EXPECT_EQ(off.newly_eroded, 0);
  EXPECT_EQ(mesh.eroded[0], 0);
  const ForceReport on = evaluate_inverted_q4(true, mesh);
  EXPECT_EQ(on.inverted_element, -1);
  EXPECT_EQ(on.newly_eroded, 1);
  EXPECT_EQ(mesh.eroded[0], 1);
  for (const Vec<2>& f : mesh.internal_force)
    EXPECT_EQ(f.squaredNorm(), 0.0);
}

/// erosion_min_step_s (LS-DYNA's ERODE with DTMIN): a unit-square Q4 at rest, squashed to height
/// h with its nodes at rest. For an a x h rectangle b_I = (+-1/2a, +-1/2h), so
/// L_e = 1 / sqrt(1/a^2 + 1/h^2), and c = sqrt(M / rho) falls as sqrt(V/V_0) = sqrt(h): the
/// step L_e / c over the one at rest is sqrt(2h / (1 + h^2)), which is 1/2 at h = 4 - sqrt(15).
bool squashed_q4_erodes(Real h, Real ratio) {
  StructuredMeshSpec<2> spec;
  spec.cells = {1, 1};
  ExplicitMesh<2> mesh = structured_mesh<2>(spec);
  SolidMaterial material;
  material.strength = materials::steel_elastic();
  material.density_kg_m3 = 7850;
  initialise<2>(mesh, material);
  material.erosion_min_step_s = ratio * stable_time_step<2>(mesh, material);
  for (Vec<2>& x : mesh.position)
    x[1] *= h;
  const ForceReport r = compute_internal_forces<2>(mesh, material, 1e-9);
  EXPECT_EQ(r.newly_eroded, mesh.eroded[0]);
  return mesh.eroded[0] != 0;
}

TEST(FemErosion, ElementBelowTheStepFloorErodes) {
  const Real h_star = 4 - std::sqrt(Real(15));  // 0.127
  EXPECT_FALSE(squashed_q4_erodes(1.0, 0.5));
  EXPECT_FALSE(squashed_q4_erodes(h_star * 1.001, 0.5));
  EXPECT_TRUE(squashed_q4_erodes(h_star * 0.999, 0.5));
  EXPECT_FALSE(squashed_q4_erodes(0.2, 0.0));  // off by default
}

}  // namespace
}  // namespace crater::fem
