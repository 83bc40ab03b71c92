// Unit tests of the strength and damage laws (src/materials/strength/, src/materials/damage/).
// Reference values are hand-computed from the closed forms quoted in each header (numbers in
// the comments); tolerances are rounding level unless a comment gives another reason.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "materials/damage/johnson_cook_damage.hpp"
#include "materials/strength/strength.hpp"

namespace crater::materials {
namespace {

constexpr Real kPi = std::numbers::pi;

Mat3 diag(Real a, Real b, Real c) {
  Mat3 m = Mat3::Zero();
  m(0, 0) = a;
  m(1, 1) = b;
  m(2, 2) = c;
  return m;
}

TEST(ElasticLaw, LameConstantsOfSteel) {
  // E = 200 GPa, nu = 0.3: lambda = 115.3846 GPa, mu = 76.9231 GPa, K = 166.667 GPa;
  // c_d = sqrt(269.23e9 / 7850) = 5856.4 m/s (the reading notes' 5,860 m/s).
  const ElasticParams steel = steel_elastic();
  EXPECT_NEAR(lame_lambda(steel), 200e9 * 0.3 / (1.3 * 0.4), 1e-3);
  EXPECT_NEAR(shear_modulus(steel), 200e9 / 2.6, 1e-3);
  EXPECT_NEAR(bulk_modulus(steel), 200e9 / 1.2, 1e-3);
  EXPECT_NEAR(dilatational_wave_speed(steel, 7850), 5856.4, 0.1);
  EXPECT_TRUE(elastic_check(steel).empty());
  EXPECT_EQ(elastic_check(ElasticParams{.youngs_modulus_pa = 1e9, .poisson_ratio = 0.5}).size(),
            1u);
}

TEST(JohnsonCookLaw, FlowStressOfThePaperSteel) {
  // eq. 41 with Table 3: at eps_p = 0.1, rate 1e3/s:
  // (50.103 + 176.091 * 0.1^0.5176) * (1 + 0.095 ln 1000) MPa
  const JohnsonCookParams p = paper_steel_johnson_cook();
  const Real hardening = 50.103e6 + 176.091e6 * std::pow(0.1, 0.5176);
  EXPECT_NEAR(johnson_cook_flow_stress(p, 0.1, 1e3, 293.15),
              hardening * (1 + 0.095 * std::log(1000.0)), 1e-6);
  // Below the reference rate no rate effect (floor r_min = 1) ...
  EXPECT_NEAR(johnson_cook_flow_stress(p, 0.1, 1e-3, 293.15), hardening, 1e-6);
  // ... unless the floor is lowered: the literal eq. 41.
  JohnsonCookParams literal = p;
  literal.min_rate_ratio = 1e-4;
  EXPECT_NEAR(johnson_cook_flow_stress(literal, 0.1, 1e-3, 293.15),
              hardening * (1 + 0.095 * std::log(1e-3)), 1e-6);
  // Thermal softening: T* = 0.5 -> factor 1 - 0.5^0.6622.
  JohnsonCookParams hot = p;
  hot.thermal_softening = true;
  const Real t_half = 0.5 * (hot.room_temperature_k + hot.melt_temperature_k);
  EXPECT_NEAR(johnson_cook_flow_stress(hot, 0.1, 1.0, t_half),
              hardening * (1 - std::pow(0.5, 0.6622)), 1e-6);
  EXPECT_EQ(johnson_cook_flow_stress(hot, 0.1, 1.0, hot.melt_temperature_k + 10), 0);
  EXPECT_TRUE(johnson_cook_check(p).empty());
}

TEST(JohnsonCookLaw, RadialReturnLandsOnTheSurfaceAlongTheTrialDeviator) {
  const JohnsonCookParams p = paper_steel_johnson_cook();
  const Real mu = shear_modulus(p.elastic);
  // A trial deviator well outside the surface (q_tr = 1 GPa), not uniaxial.
  Mat3 s = deviator(diag(700e6, -100e6, 50e6));
  s(0, 1) = s(1, 0) = 120e6;
  s *= 1e9 / std::sqrt(3 * second_invariant(s));
  const JohnsonCookState state{.plastic_strain = 0.05, .temperature_k = 293.15};
  const Real dt = 1e-6;
  const RadialReturn r = johnson_cook_radial_return(p, s, state, dt, 7850);
  ASSERT_TRUE(r.yielded);
  const Real q = std::sqrt(3 * second_invariant(r.deviator));
  const Real dep = r.plastic_strain_increment;
  // On eq. 41 at the new plastic strain and the step's plastic strain rate.
  const Real sigma_y = johnson_cook_flow_stress(p, 0.05 + dep, dep / dt, 293.15);
  EXPECT_NEAR(q, sigma_y, 1e-12 * sigma_y);
  // Radial: q_new = q_tr - 3 mu dep, same direction.
  EXPECT_NEAR(q, 1e9 - 3 * mu * dep, 1e-12 * 1e9);
  EXPECT_LT((r.deviator / q - s / 1e9).norm(), 1e-12);
  EXPECT_NEAR(r.plastic_work_j_m3, q * dep, 1e-9 * q * dep);
  // Inside the surface: elastic, untouched.
  const RadialReturn e = johnson_cook_radial_return(p, s * 1e-2, state, dt, 7850);
  EXPECT_FALSE(e.yielded);
  EXPECT_EQ(e.plastic_strain_increment, 0);
  EXPECT_EQ((e.deviator - s * 1e-2).norm(), 0);
}

// The return's Newton changes variable (x or ln x) at the rate floor's kink x = dt eps_dot0: the
// roots on either side of it, at it, and far beyond must all land on eq. 41.
TEST(JohnsonCookLaw, RadialReturnLandsOnTheSurfaceOnBothSidesOfTheRateKink) {
  const JohnsonCookParams p = paper_steel_johnson_cook();
  const Real mu = shear_modulus(p.elastic);
  for (const Real dt : {9e-8, 1e-6}) {
    for (const Real eps0 : {0.0, 0.01, 0.5}) {
      for (const Real over : {1e-4, 1e-3, 1e-2, 0.1, 0.5, 2.0, 20.0}) {
        SCOPED_TRACE(::testing::Message() << "dt " << dt << " eps0 " << eps0 << " over " << over);
        const JohnsonCookState state{.plastic_strain = eps0, .temperature_k = 293.15};
        const Real q_tr = johnson_cook_flow_stress(p, eps0, 0, 293.15) * (1 + over);
        Mat3 s = Mat3::Zero();
        s(0, 1) = s(1, 0) = q_tr / std::sqrt(3.0);
        const RadialReturn r = johnson_cook_radial_return(p, s, state, dt, 7850);
        ASSERT_TRUE(r.yielded);
        const Real dep = r.plastic_strain_increment;
        ASSERT_GT(dep, 0);
        const Real q = q_tr - 3 * mu * dep;
        EXPECT_NEAR(q, johnson_cook_flow_stress(p, eps0 + dep, dep / dt, 293.15), 1e-12 * q_tr);
      }
    }
  }
  // Without hardening and rate, the return is the perfectly plastic one in closed form.
  JohnsonCookParams flat = p;
  flat.b_pa = 0;
  flat.c = 0;
  Mat3 s = Mat3::Zero();
  s(0, 1) = s(1, 0) = 3 * flat.a_pa / std::sqrt(3.0);
  const RadialReturn r = johnson_cook_radial_return(flat, s, JohnsonCookState{}, 1e-7, 7850);
  EXPECT_NEAR(r.plastic_strain_increment, 2 * flat.a_pa / (3 * mu), 1e-14);
}

TEST(JohnsonCookLaw, AdiabaticHeatingIsTaylorQuinneyFractionOfPlasticWork) {
  JohnsonCookParams p = paper_steel_johnson_cook();
  p.thermal_softening = true;
  const Mat3 s = deviator(diag(1e9, 0, 0));
  const RadialReturn r = johnson_cook_radial_return(p, s, JohnsonCookState{}, 1e-6, 7850);
  EXPECT_NEAR(r.temperature_increment_k, 0.9 * r.plastic_work_j_m3 / (7850 * 486.0),
              1e-12 * r.temperature_increment_k);
  EXPECT_GT(r.temperature_increment_k, 0);
}

TEST(JohnsonCookDamage, TriaxialityAndFailureStrain) {
  // sigma* = sigma_m / sigma_vm: uniaxial tension 1/3, equibiaxial tension 2/3, uniaxial
  // compression -1/3, pure shear 0.
  EXPECT_NEAR(stress_triaxiality(diag(100, 0, 0)), 1.0 / 3, 1e-15);
  EXPECT_NEAR(stress_triaxiality(diag(100, 100, 0)), 2.0 / 3, 1e-15);
  EXPECT_NEAR(stress_triaxiality(diag(-100, 0, 0)), -1.0 / 3, 1e-15);
  EXPECT_NEAR(stress_triaxiality(diag(100, -100, 0)), 0, 1e-15);
  EXPECT_EQ(stress_triaxiality(diag(-5, -5, -5)), 0);
  // Table 3: eps_f(1/3, 1e3/s, T*=0) = (0.05 + 3.44 e^{-2.12/3})(1 + 0.002 ln 1000).
  const JohnsonCookDamageParams d = paper_steel_johnson_cook_damage();
  EXPECT_NEAR(johnson_cook_failure_strain(d, 1.0 / 3, 1e3, 293.15),
              (0.05 + 3.44 * std::exp(-2.12 / 3)) * (1 + 0.002 * std::log(1000.0)), 1e-14);
  EXPECT_NEAR(johnson_cook_damage_increment(d, 0.01, 0, 1, 293.15), 0.01 / 3.49, 1e-15);
  EXPECT_EQ(johnson_cook_damage_increment(d, 0, 0, 1, 293.15), 0);
  EXPECT_FALSE(johnson_cook_failed(0.999));
  EXPECT_TRUE(johnson_cook_failed(1.0));
}

/// Drucker-Prager for a sand-like soil: E = 50 MPa, nu = 0.3, c = 10 kPa, phi = 30 deg.
DruckerPragerParams soil(Real dilation_deg) {
  return drucker_prager_from_mohr_coulomb(
      ElasticParams{.youngs_modulus_pa = 50e6, .poisson_ratio = 0.3}, 10e3, 30 * kPi / 180,
      dilation_deg * kPi / 180, MohrCoulombFit::kCompressionCone);
}

TEST(DruckerPragerLaw, MohrCoulombFitReproducesTriaxialCompressionStrength) {
  // Outer cone: in triaxial compression (sigma_1 = sigma_2 = -confinement > sigma_3) DP and
  // MC give the same strength: sigma_1 - sigma_3 = 2 c cos phi / (1 - sin phi) + confinement *
  // 2 sin phi / (1 - sin phi) (Mohr-Coulomb, tension positive, compression on the axis).
  const DruckerPragerParams p = soil(30);
  const Real phi = 30 * kPi / 180, c = 10e3, confinement = 100e3;
  const Real deviator_mc =
      (2 * c * std::cos(phi) + 2 * confinement * std::sin(phi)) / (1 - std::sin(phi));
  const Mat3 at_failure = diag(-confinement - deviator_mc, -confinement, -confinement);
  EXPECT_NEAR(drucker_prager_yield(p, at_failure), 0, 1e-9 * p.k_pa);
}

TEST(DruckerPragerLaw, ReturnLiesOnTheConeInTriaxialCompression) {
  // Brief: |f| <= 1e-8 k after the return, for associative and non-associative flow.
  for (const Real dilation : {30.0, 10.0, 0.0}) {
    const DruckerPragerParams p = soil(dilation);
    for (const Real axial : {-0.5e6, -2e6, -20e6}) {
      const Mat3 trial = diag(axial, -100e3, -100e3);
      ASSERT_GT(drucker_prager_yield(p, trial), 0);
      const DruckerPragerReturn r = drucker_prager_return(p, trial);
      EXPECT_TRUE(r.yielded);
      EXPECT_FALSE(r.apex);
      EXPECT_LE(std::abs(drucker_prager_yield(p, r.stress)), 1e-8 * p.k_pa)
          << "dilation " << dilation << " axial " << axial;
      // Triaxial symmetry is kept (sigma_2 = sigma_3).
      EXPECT_NEAR(r.stress(1, 1), r.stress(2, 2), 1e-9 * std::abs(axial));
      // The plastic strain C^{-1}(trial - sigma) points along the potential's gradient
      // s / (2 sqrt J2) + beta I (the flow rule): its deviatoric / volumetric split.
      const Real mu = shear_modulus(p.elastic), bulk = bulk_modulus(p.elastic);
      const Mat3 ds = deviator(trial - r.stress) / (2 * mu);
      const Real dv = (trial - r.stress).trace() / (3 * bulk);  // tr of plastic strain
      const Mat3 s = deviator(r.stress);
      const Real sqrt_j2 = std::sqrt(second_invariant(s));
      EXPECT_LT((ds - r.plastic_multiplier * s / (2 * sqrt_j2)).norm(), 1e-9 * ds.norm());
      EXPECT_NEAR(dv, 3 * p.beta * r.plastic_multiplier, 1e-9 * std::abs(dv) + 1e-14);
      EXPECT_GE(r.plastic_work_j_m3, 0);
    }
  }
}

TEST(DruckerPragerLaw, TensionBeyondTheApexReturnsToTheApex) {
  const DruckerPragerParams p = soil(30);
  const Mat3 trial = diag(200e3, 150e3, 180e3);  // hydrostatic tension far past the apex
  const DruckerPragerReturn r = drucker_prager_return(p, trial);
  EXPECT_TRUE(r.apex);
  EXPECT_LT(deviator(r.stress).norm(), 1e-9 * p.k_pa);
  EXPECT_NEAR(r.stress.trace(), p.k_pa / p.alpha, 1e-9 * p.k_pa / p.alpha);
  EXPECT_LE(std::abs(drucker_prager_yield(p, r.stress)), 1e-8 * p.k_pa);
}

TEST(DruckerPragerLaw, ZeroFrictionIsVonMisesRadialReturn) {
  // alpha = 0: the cone is the von Mises cylinder sqrt(J2) = k, i.e. sigma_y = sqrt(3) k; the
  // return must equal the J2 radial return of a perfectly plastic Johnson-Cook (B = C = 0).
  const ElasticParams el = steel_elastic();
  const DruckerPragerParams dp{.elastic = el, .alpha = 0, .k_pa = 200e6, .beta = 0};
  const JohnsonCookParams jc{.elastic = el, .a_pa = std::sqrt(3.0) * 200e6, .b_pa = 0, .c = 0};
  Mat3 trial = diag(900e6, -100e6, 300e6);
  trial(0, 2) = trial(2, 0) = 50e6;
  const StressUpdate a =
      update_stress_of(dp, trial, Mat3::Zero(), MaterialPointState{}, 1e-6, 7850);
  const StressUpdate b =
      update_stress_of(jc, trial, Mat3::Zero(), MaterialPointState{}, 1e-6, 7850);
  EXPECT_LT((a.stress - b.stress).norm(), 1e-6);
  EXPECT_NEAR(a.plastic_strain_increment, b.plastic_strain_increment, 1e-15);
}

TEST(StrengthLaws, ChecksFlagBadConstants) {
  EXPECT_TRUE(strength_check(StrengthParams{soil(10)}).empty());
  DruckerPragerParams bad = soil(10);
  bad.beta = 2 * bad.alpha;
  EXPECT_FALSE(drucker_prager_check(bad).empty());
  JohnsonCookParams jc = paper_steel_johnson_cook();
  jc.min_rate_ratio = 1e-10;  // 1 + 0.095 ln 1e-10 < 0
  EXPECT_FALSE(johnson_cook_check(jc).empty());
}

}  // namespace
}  // namespace crater::materials
