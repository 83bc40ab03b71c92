// Unit tests of the Holmquist-Johnson-Cook concrete law
// (src/materials/strength/holmquist_johnson_cook.hpp) with the 48 MPa set of Holmquist, Johnson
// & Cook (1993). Every expected value is the header's closed form typed out here with that set's
// numbers (hand calculation in the comments), never the law's own helpers; tolerance 1e-6
// relative.
//
// Numbers used throughout: K_e = P_c/mu_c = 16e6/0.001 = 16 GPa; G = 14.86 GPa; f_c = 48 MPa;
// T = 4 MPa. The fully dense curve reaches P_l = 0.8 GPa at x_l solving
// 85e9 x - 171e9 x^2 + 208e9 x^3 = 0.8e9: x_l = 0.009594806918588571 (bisection in 40-digit
// decimal arithmetic, outside crater), so mu_plock = 0.1 + 1.1 x_l = 0.11055428761044743.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "materials/strength/holmquist_johnson_cook.hpp"

namespace crater::materials {
namespace {

constexpr Real kRelTol = 1e-6;
constexpr Real kG = 14.86e9;
constexpr Real kKe = 16e9;
constexpr Real kFc = 48e6;
constexpr Real kT = 4e6;
constexpr Real kMuPlock = 0.11055428761044743;

void expect_rel(Real actual, Real expected) {
  EXPECT_NEAR(actual, expected, kRelTol * std::abs(expected)) << "expected " << expected;
}

/// The 48 MPa crush line: 16 MPa + (800 - 16) MPa (mu - 0.001)/(mu_plock - 0.001).
Real crush_line(Real mu) {
  return 16e6 + (800e6 - 16e6) * (mu - 0.001) / (kMuPlock - 0.001);
}

/// Unloading modulus of region II: (1 - F) 16 GPa + F 85 GPa, F = (mu_max - 0.001)/(mu_plock -
/// 0.001).
Real unloading_modulus(Real mu_max) {
  const Real f = (mu_max - 0.001) / (kMuPlock - 0.001);
  return (1 - f) * 16e9 + f * 85e9;
}

TEST(HolmquistJohnsonCookEos, LockCompressionIsWhereTheDenseCurveReachesPlock) {
  const Real x = 0.009594806918588571;
  // The typed root: 85e9 x - 171e9 x^2 + 208e9 x^3 is 0.8 GPa.
  expect_rel(85e9 * x - 171e9 * x * x + 208e9 * x * x * x, 0.8e9);
  const HjcEosConstants c = hjc_eos_constants(holmquist_johnson_cook_48mpa_concrete());
  expect_rel(c.k_elastic_pa, kKe);
  expect_rel(c.mu_plock, kMuPlock);
  expect_rel(c.k_crush_pa, (800e6 - 16e6) / (kMuPlock - 0.001));
}

TEST(HolmquistJohnsonCookEos, PressureInTheThreeRegionsAndOnUnloading) {
  const HolmquistJohnsonCookParams p = holmquist_johnson_cook_48mpa_concrete();
  // Region I (elastic), loading and unloading alike: 16 GPa x 5e-4 = 8 MPa.
  expect_rel(hjc_pressure(p, 5e-4, 0, 0), 8e6);
  expect_rel(hjc_pressure(p, 2e-4, 8e-4, 0), 3.2e6);
  // Region I in tension: 16 GPa x (-1e-4) = -1.6 MPa; beyond the cutoff -T(1 - D).
  expect_rel(hjc_pressure(p, -1e-4, 0, 0), -1.6e6);
  expect_rel(hjc_pressure(p, -1e-3, 0, 0), -4e6);
  expect_rel(hjc_pressure(p, -1e-3, 0, 0.25), -3e6);
  // Region II, loading at mu = 0.05: 16e6 + 784e6 (0.049 / 0.10955428761044743) = 366.66 MPa.
  expect_rel(hjc_pressure(p, 0.05, 0, 0), 16e6 + 784e6 * 0.049 / (kMuPlock - 0.001));
  expect_rel(hjc_pressure(p, 0.05, 0.03, 0), crush_line(0.05));
  // Region II, unloading from mu_max = 0.05 to 0.045 along Kbar = (1 - F) 16 + F 85 GPa,
  // F = 0.049 / 0.10955428761044743 = 0.44727: Kbar = 46.862 GPa, p = 366.66 - 234.31 MPa.
  const Real f = 0.049 / (kMuPlock - 0.001);
  const Real k_bar = (1 - f) * 16e9 + f * 85e9;
  expect_rel(hjc_pressure(p, 0.045, 0.05, 0), crush_line(0.05) - k_bar * 0.005);
  // ... and reloading beyond mu_max rejoins the crush line; far enough down, the cutoff.
  expect_rel(hjc_pressure(p, 0.06, 0.05, 0), crush_line(0.06));
  expect_rel(hjc_pressure(p, 0.04, 0.05, 0), -4e6);
  // Region III (fully dense), loading at mu = 0.15: mubar = 0.05/1.1.
  const Real x = 0.05 / 1.1;
  expect_rel(hjc_pressure(p, 0.15, 0, 0), 85e9 * x - 171e9 * x * x + 208e9 * x * x * x);
  // ... unloading from 0.15 to 0.12 on the same curve: mubar = 0.02/1.1.
  const Real y = 0.02 / 1.1;
  expect_rel(hjc_pressure(p, 0.12, 0.15, 0), 85e9 * y - 171e9 * y * y + 208e9 * y * y * y);
  // ... below mu_lock linear in tension: 85 GPa (-4e-5/1.1) = -3.0909 MPa; then the cutoff.
  expect_rel(hjc_pressure(p, 0.09996, 0.15, 0), 85e9 * (-4e-5 / 1.1));
  expect_rel(hjc_pressure(p, 0.0999, 0.15, 0), -4e6);
  // The loading curve is continuous at the crush point and at the lock point.
  expect_rel(hjc_pressure(p, 0.001, 0, 0), 16e6);
  expect_rel(hjc_pressure(p, kMuPlock * (1 - 1e-12), 0, 0), 0.8e9);
  expect_rel(hjc_pressure(p, kMuPlock * (1 + 1e-12), 0, 0), 0.8e9);
}

TEST(HolmquistJohnsonCookEos, PlasticVolumetricStrainIsTheZeroPressureIntercept) {
  const HolmquistJohnsonCookParams p = holmquist_johnson_cook_48mpa_concrete();
  const HjcEosConstants c = hjc_eos_constants(p);
  EXPECT_EQ(hjc_plastic_volumetric_strain(p, c, 5e-4), 0);
  // mu_max = 0.05: 0.05 - 366.66 MPa / 46.862 GPa = 0.04218.
  expect_rel(hjc_plastic_volumetric_strain(p, c, 0.05),
             0.05 - crush_line(0.05) / unloading_modulus(0.05));
  // Fully dense: frozen at the lock point, mu_plock - 0.8 GPa / 85 GPa = 0.101143.
  expect_rel(hjc_plastic_volumetric_strain(p, c, 0.2), kMuPlock - 0.8e9 / 85e9);
}

TEST(HolmquistJohnsonCookStrength, SurfaceAtThreePressuresAndTwoRates) {
  const HolmquistJohnsonCookParams p = holmquist_johnson_cook_48mpa_concrete();
  // Rate factors: 1/s is the reference (1); 100/s: 1 + 0.007 ln 100 = 1.032236.
  const Real fast = 1 + 0.007 * std::log(100.0);
  // P* = 0.5 (24 MPa): 0.79 + 1.6 x 0.5^0.61 = 1.81666.
  const Real s_low = 0.79 + 1.6 * std::pow(0.5, 0.61);
  expect_rel(hjc_normalized_strength(p, 24e6, 0, 1.0), s_low);
  expect_rel(hjc_normalized_strength(p, 24e6, 0, 100.0), s_low * fast);
  // P* = 2 (96 MPa): 0.79 + 1.6 x 2^0.61 = 3.23380.
  const Real s_mid = 0.79 + 1.6 * std::pow(2.0, 0.61);
  expect_rel(hjc_normalized_strength(p, 96e6, 0, 1.0), s_mid);
  expect_rel(hjc_normalized_strength(p, 96e6, 0, 100.0), s_mid * fast);
  // P* = 10 (480 MPa): 0.79 + 1.6 x 10^0.61 = 7.3081 > S_max: capped at 7 at both rates.
  ASSERT_GT(0.79 + 1.6 * std::pow(10.0, 0.61), 7.0);
  expect_rel(hjc_normalized_strength(p, 480e6, 0, 1.0), 7.0);
  expect_rel(hjc_normalized_strength(p, 480e6, 0, 100.0), 7.0);
  // Damage softens the cohesive part only: D = 0.5 at P* = 2: 0.79 x 0.5 + 1.6 x 2^0.61.
  expect_rel(hjc_normalized_strength(p, 96e6, 0.5, 1.0), 0.395 + 1.6 * std::pow(2.0, 0.61));
  // Below the reference rate no softening: 0.01/s gives the 1/s value.
  expect_rel(hjc_normalized_strength(p, 24e6, 0, 0.01), s_low);
  // Tension, p = -2 MPa, D = 0.2: 0.79 (1 - 2/4)(1 - 0.2) = 0.316; zero at p = -T.
  expect_rel(hjc_normalized_strength(p, -2e6, 0.2, 1.0), 0.316);
  expect_rel(hjc_normalized_strength(p, -2e6, 0.2, 100.0), 0.316 * fast);
  EXPECT_EQ(hjc_normalized_strength(p, -4e6, 0, 1.0), 0);
  // Both branches give A(1 - D) at zero pressure.
  expect_rel(hjc_normalized_strength(p, 0, 0.3, 1.0), 0.79 * 0.7);
  expect_rel(hjc_normalized_strength(p, -1e-3, 0.3, 1.0), 0.79 * 0.7 * (1 - 1e-3 / 4e6));
}

TEST(HolmquistJohnsonCookDamage, FractureStrainHasItsFloor) {
  const HolmquistJohnsonCookParams p = holmquist_johnson_cook_48mpa_concrete();
  // p = 100 MPa: 0.04 (100 + 4)/48 = 0.086667; p = 0: 0.04 x 4/48 = 0.00333 < EF_min = 0.01.
  expect_rel(hjc_fracture_strain(p, 100e6), 0.04 * 104.0 / 48.0);
  expect_rel(hjc_fracture_strain(p, 0), 0.01);
  expect_rel(hjc_fracture_strain(p, -4e6), 0.01);
  expect_rel(hjc_damage_increment(p, 1e-3, 2e-3, 100e6), 3e-3 / (0.04 * 104.0 / 48.0));
}

Mat3 uniaxial_strain(Real e) {
  Mat3 m = Mat3::Zero();
  m(0, 0) = e;
  return m;
}

// One material point pulled in uniaxial strain, 1e-4 per step, dt = 1 s (strain rate
// 2/3 x 1e-4 /s below the reference rate: no rate effect); density rho0/(1 + n 1e-4) after step
// n. Each step adds 2G dev(de) to the deviator, i.e. dq = 2 G 1e-4 = 2.972 MPa to q.
TEST(HolmquistJohnsonCookDamage, UniaxialStrainTensionAgainstAHandCalculation) {
  const HolmquistJohnsonCookParams p = holmquist_johnson_cook_48mpa_concrete();
  const Real dq = 2 * kG * 1e-4;
  const Real a = 0.79;
  HjcState state;
  Mat3 stress = Mat3::Zero();
  auto step = [&](int n) {
    const HjcStressUpdate u =
        update_stress_of(p, stress, uniaxial_strain(1e-4), state, 1.0, 2440.0 / (1 + n * 1e-4));
    stress = u.stress;
    state = u.state;
    return u;
  };
  // Step 1: mu = 1/1.0001 - 1, p = K_e mu = -1.59984 MPa (above -T); sigma* = 0.79 (1 + p/T)
  // = 0.47403, sigma_y = 22.75 MPa > q = 2.972 MPa: elastic. sigma_xx = (2/3) q - p.
  HjcStressUpdate u = step(1);
  const Real p1 = kKe * (1 / 1.0001 - 1);
  expect_rel(u.pressure_pa, p1);
  expect_rel(u.yield_stress_pa, kFc * a * (1 + p1 / kT));
  expect_rel(u.stress(0, 0), 2.0 / 3 * dq - p1);
  expect_rel(u.stress(1, 1), -1.0 / 3 * dq - p1);
  EXPECT_EQ(state.damage, 0);
  // Step 2: p = K_e (1/1.0002 - 1) = -3.19936 MPa, sigma_y = 7.590 MPa > q = 5.944 MPa.
  u = step(2);
  const Real p2 = kKe * (1 / 1.0002 - 1);
  expect_rel(u.pressure_pa, p2);
  expect_rel(u.stress(0, 0), 2.0 / 3 * 2 * dq - p2);
  EXPECT_EQ(u.plastic_strain_increment, 0);
  EXPECT_EQ(state.damage, 0);
  // Step 3: K_e mu = -4.7986 MPa is below -T: p = -4 MPa, where sigma* = 0.79 (1 - 4/4) = 0, so
  // all of q = 3 dq = 8.916 MPa flows: d_eps_p = 8.916e6 / (3 G) = 2e-4. eps_f = max(0.01,
  // 0.04 (p + T)/f_c = 0) = 0.01: D = 2e-4/0.01 = 0.02. Stress: 4 MPa hydrostatic tension.
  u = step(3);
  expect_rel(u.pressure_pa, -4e6);
  EXPECT_EQ(u.yield_stress_pa, 0);
  expect_rel(u.plastic_strain_increment, 3 * dq / (3 * kG));
  expect_rel(u.plastic_strain_increment, 2e-4);
  expect_rel(state.damage, 0.02);
  expect_rel(u.stress(0, 0), 4e6);
  expect_rel(u.stress(1, 1), 4e6);
  // Step 4: cutoff -T (1 - 0.02) = -3.92 MPa (K_e mu = -6.4 MPa). sigma* = 0.79 (1 - 3.92/4)
  // (1 - 0.02) = 0.015484, sigma_y = 0.743232 MPa < q = dq: d_eps_p = (dq - sigma_y)/(3 G);
  // eps_f = max(0.01, 0.04 x 0.08/48) = 0.01.
  u = step(4);
  const Real p4 = -kT * (1 - 0.02);
  const Real sy4 = kFc * a * (1 + p4 / kT) * (1 - 0.02);
  expect_rel(sy4, 0.743232e6);
  const Real dep4 = (dq - sy4) / (3 * kG);
  const Real d4 = 0.02 + dep4 / 0.01;
  expect_rel(u.pressure_pa, p4);
  expect_rel(u.yield_stress_pa, sy4);
  expect_rel(u.plastic_strain_increment, dep4);
  expect_rel(state.damage, d4);
  expect_rel(u.stress(0, 0), 2.0 / 3 * sy4 - p4);
  // Step 5: cutoff -T (1 - D4); sigma_y = f_c 0.79 (1 + p/T)(1 - D4); q = sigma_y4 + dq.
  u = step(5);
  const Real p5 = -kT * (1 - d4);
  const Real sy5 = kFc * a * (1 + p5 / kT) * (1 - d4);
  const Real dep5 = (sy4 + dq - sy5) / (3 * kG);
  expect_rel(u.pressure_pa, p5);
  expect_rel(u.plastic_strain_increment, dep5);
  expect_rel(state.damage, d4 + dep5 / 0.01);
  expect_rel(state.plastic_strain, 2e-4 + dep4 + dep5);
  EXPECT_EQ(state.plastic_volumetric_strain, 0);
  EXPECT_EQ(state.mu_max, 0);
}

// One material point crushed in uniaxial strain (confined compression), -2e-3 per step, dt = 1 s
// (no rate effect); density rho0/(1 - n 2e-3). Each step adds dq = 2 G 2e-3 = 59.44 MPa to q.
// Region II from the first step: damage from crushing first, then from shear as well.
TEST(HolmquistJohnsonCookDamage, ConfinedCompressionAgainstAHandCalculation) {
  const HolmquistJohnsonCookParams p = holmquist_johnson_cook_48mpa_concrete();
  const Real dq = 2 * kG * 2e-3;
  HjcState state;
  Mat3 stress = Mat3::Zero();
  auto step = [&](int n) {
    const HjcStressUpdate u =
        update_stress_of(p, stress, uniaxial_strain(-2e-3), state, 1.0, 2440.0 / (1 - n * 2e-3));
    stress = u.stress;
    state = u.state;
    return u;
  };
  // Step 1: mu1 = 1/0.998 - 1 = 0.002004 > mu_c: on the crush line, p1 = 23.185 MPa;
  // mu_p1 = mu1 - p1/Kbar(mu1) = 6.1004e-4. sigma_y = 48 MPa (0.79 + 1.6 (p1/48 MPa)^0.61)
  // = 87.19 MPa > q = 59.44 MPa: elastic. eps_f = 0.04 (p1 + 4 MPa)/48 MPa = 0.022654;
  // D1 = mu_p1 / eps_f.
  HjcStressUpdate u = step(1);
  const Real mu1 = 1 / 0.998 - 1;
  const Real p1 = crush_line(mu1);
  const Real mup1 = mu1 - p1 / unloading_modulus(mu1);
  const Real d1 = mup1 / (0.04 * (p1 + kT) / kFc);
  expect_rel(u.pressure_pa, p1);
  expect_rel(u.yield_stress_pa, kFc * (0.79 + 1.6 * std::pow(p1 / kFc, 0.61)));
  EXPECT_EQ(u.plastic_strain_increment, 0);
  expect_rel(u.plastic_volumetric_strain_increment, mup1);
  expect_rel(state.damage, d1);
  // Step 2: mu2 = 1/0.996 - 1, p2 = 37.58 MPa; d_mu_p = mu_p2 - mu_p1. sigma_y with D1:
  // 48 MPa (0.79 (1 - D1) + 1.6 (p2/48 MPa)^0.61) = 103.05 MPa < q = 2 dq = 118.88 MPa:
  // d_eps_p = (q - sigma_y)/(3 G). D2 = D1 + (d_eps_p + d_mu_p)/(0.04 (p2 + 4 MPa)/48 MPa).
  u = step(2);
  const Real mu2 = 1 / 0.996 - 1;
  const Real p2 = crush_line(mu2);
  const Real dmup2 = mu2 - p2 / unloading_modulus(mu2) - mup1;
  const Real sy2 = kFc * (0.79 * (1 - d1) + 1.6 * std::pow(p2 / kFc, 0.61));
  const Real dep2 = (2 * dq - sy2) / (3 * kG);
  const Real d2 = d1 + (dep2 + dmup2) / (0.04 * (p2 + kT) / kFc);
  expect_rel(u.pressure_pa, p2);
  expect_rel(u.yield_stress_pa, sy2);
  expect_rel(u.plastic_strain_increment, dep2);
  expect_rel(u.plastic_volumetric_strain_increment, dmup2);
  expect_rel(state.damage, d2);
  // Step 3: q = sigma_y2 + dq; sigma_y with D2; the stress lies on the surface:
  // sigma_xx = -(2/3) sigma_y - p, sigma_yy = (1/3) sigma_y - p.
  u = step(3);
  const Real mu3 = 1 / 0.994 - 1;
  const Real p3 = crush_line(mu3);
  const Real mup3 = mu3 - p3 / unloading_modulus(mu3);
  const Real sy3 = kFc * (0.79 * (1 - d2) + 1.6 * std::pow(p3 / kFc, 0.61));
  const Real dep3 = (sy2 + dq - sy3) / (3 * kG);
  const Real d3 = d2 + (dep3 + mup3 - (mup1 + dmup2)) / (0.04 * (p3 + kT) / kFc);
  expect_rel(u.pressure_pa, p3);
  expect_rel(u.plastic_strain_increment, dep3);
  expect_rel(state.damage, d3);
  expect_rel(state.plastic_volumetric_strain, mup3);
  expect_rel(state.plastic_strain, dep2 + dep3);
  expect_rel(state.mu_max, mu3);
  expect_rel(u.stress(0, 0), -2.0 / 3 * sy3 - p3);
  expect_rel(u.stress(1, 1), 1.0 / 3 * sy3 - p3);
}

TEST(HolmquistJohnsonCookCheck, PublishedSetPassesAndImpossibleConstantsAreNamed) {
  const HolmquistJohnsonCookParams good = holmquist_johnson_cook_48mpa_concrete();
  EXPECT_TRUE(holmquist_johnson_cook_check(good).empty());
  EXPECT_TRUE(strength_check_of(good).empty());
  auto first_key = [](const HolmquistJohnsonCookParams& p) {
    const auto problems = holmquist_johnson_cook_check(p);
    return problems.empty() ? std::string() : problems.front().key;
  };
  HolmquistJohnsonCookParams bad = good;
  bad.mu_lock = 0.001;  // not beyond the crush strain
  EXPECT_EQ(first_key(bad), "mu_lock");
  bad = good;
  bad.shear_modulus_pa = -1e9;
  EXPECT_EQ(first_key(bad), "shear_modulus_pa");
  bad = good;
  bad.p_lock_pa = 10e6;  // below the crush pressure
  EXPECT_EQ(first_key(bad), "p_lock_pa");
  bad = good;
  bad.ef_min = 0;
  EXPECT_EQ(first_key(bad), "ef_min");
  bad = good;
  bad.k2_pa = -5000e9;  // the dense curve falls (slope 85e9 - 1e13 x + 624e9 x^2 < 0) first
  EXPECT_EQ(first_key(bad), "k2_pa");
}

TEST(HolmquistJohnsonCookLaw, PrecomputedEosGivesTheSameBits) {
  // The FEM loop passes the EOS constants derived once; the one-shot overload derives them.
  const HolmquistJohnsonCookParams p = holmquist_johnson_cook_48mpa_concrete();
  const HolmquistJohnsonCookLaw law = holmquist_johnson_cook_law(p);
  Mat3 strain = Mat3::Zero();
  strain(0, 0) = -2e-3;
  const HjcState state{.damage = 0.1, .mu_max = 0.02, .plastic_volumetric_strain = 0.01};
  const HjcStressUpdate a = update_stress_of(p, Mat3::Zero(), strain, state, 1e-6, 2440 * 1.03);
  const HjcStressUpdate b =
      update_stress_of(law.params, law.eos, Mat3::Zero(), strain, state, 1e-6, 2440 * 1.03);
  EXPECT_EQ(a.stress, b.stress);
  EXPECT_EQ(a.state.damage, b.state.damage);
  EXPECT_EQ(a.state.mu_max, b.state.mu_max);
  EXPECT_EQ(a.state.plastic_volumetric_strain, b.state.plastic_volumetric_strain);
  EXPECT_TRUE(strength_check_of(law).empty());
}

TEST(HolmquistJohnsonCookLaw, ElasticConstantsAndWaveModulus) {
  // K_max = max(K_e, K_crush, K_1) = max(16, 784e6/(mu_plock - 0.001) = 7.156, 85) GPa = K_1.
  const HolmquistJohnsonCookLaw law =
      holmquist_johnson_cook_law(holmquist_johnson_cook_48mpa_concrete());
  expect_rel(law.max_bulk_modulus_pa, 85e9);
  expect_rel(bulk_modulus(law.elastic), 85e9);
  expect_rel(shear_modulus(law.elastic), kG);
  expect_rel(bulk_modulus(law.at_rest), kKe);
  expect_rel(shear_modulus(law.at_rest), kG);
  // (1 + mu) K_1 below the dense cubic's own rise past K_1; beyond it (1 + mu) dp/dmu with
  // dp/dmu = (85 - 342 x + 624 x^2) GPa / 1.1, x = (mu - 0.1)/1.1 (x = 0.7/1.1 at mu = 0.8).
  expect_rel(hjc_wave_bulk_modulus(law, 0), 85e9);
  expect_rel(hjc_wave_bulk_modulus(law, -0.01), 85e9);
  expect_rel(hjc_wave_bulk_modulus(law, 0.05), 1.05 * 85e9);
  expect_rel(hjc_wave_bulk_modulus(law, 0.3), 1.3 * 85e9);  // x = 0.18: slope 43 GPa / 1.1
  const Real x = 0.7 / 1.1;
  expect_rel(hjc_wave_bulk_modulus(law, 0.8), 1.8 * (85e9 - 342e9 * x + 624e9 * x * x) / 1.1);
}

}  // namespace
}  // namespace crater::materials
