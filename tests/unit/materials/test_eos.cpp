// Unit tests of the equations of state (src/materials/eos/).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "materials/eos/eos.hpp"

namespace crater::materials {
namespace {

/// Sound speed from the thermodynamic identity, by central differences of the pressure alone:
///   c^2 = (\partial p/\partial \rho)_e + (p/\rho^2) (\partial p/\partial e)_\rho.
/// Relative steps 1e-6 give truncation ~1e-12 and rounding ~1e-10 relative to p.
template <class Law>
Real finite_difference_sound_speed(const Law& law, Real rho, Real e) {
  const Real d_rho = 1e-6 * rho;
  const Real d_e = 1e-6 * std::max(std::abs(e), Real(1));
  const Real dp_drho =
      (eos_pressure_of(law, rho + d_rho, e) - eos_pressure_of(law, rho - d_rho, e)) / (2 * d_rho);
  const Real dp_de =
      (eos_pressure_of(law, rho, e + d_e) - eos_pressure_of(law, rho, e - d_e)) / (2 * d_e);
  const Real p = eos_pressure_of(law, rho, e);
  return std::sqrt(dp_drho + p / (rho * rho) * dp_de);
}

bool any_contains(const std::vector<ConstantProblem>& problems, const std::string& needle) {
  return std::ranges::any_of(problems, [&needle](const ConstantProblem& p) {
    return p.message.find(needle) != std::string::npos;
  });
}

std::string joined(const std::vector<ConstantProblem>& problems) {
  std::string all;
  for (const auto& p : problems) {
    all += p.key + ": " + p.message + "\n";
  }
  return all;
}

// ---------------------------------------------------------------- ideal gas

TEST(IdealGasEos, PressureAndSoundSpeedAtSeaLevel) {
  // ISA sea level: rho = 1.225 kg/m^3, p = 101325 Pa, gamma = 1.4 -> c = 340.294 m/s
  // (ICAO Standard Atmosphere, Doc 7488).
  const IdealGasParams air{.gamma = 1.4};
  const Real rho = 1.225;
  const Real e = 101325.0 / (0.4 * rho);
  const Real p = ideal_gas_pressure(air, rho, e);
  EXPECT_NEAR(p, 101325.0, 1e-9);
  EXPECT_NEAR(ideal_gas_sound_speed(air, rho, e, p), 340.294, 1e-3);
}

TEST(IdealGasEos, SoundSpeedMatchesFiniteDifference) {
  const IdealGasParams gas{.gamma = 5.0 / 3.0};
  for (const Real rho : {0.01, 1.0, 1000.0}) {
    for (const Real e : {1e3, 2.5e5, 1e7}) {
      const Real c = ideal_gas_sound_speed(gas, rho, e, ideal_gas_pressure(gas, rho, e));
      EXPECT_NEAR(c, finite_difference_sound_speed(gas, rho, e), 1e-7 * c);
    }
  }
}

TEST(IdealGasEos, CheckRejectsGammaAtMostOne) {
  EXPECT_TRUE(ideal_gas_check(IdealGasParams{.gamma = 1.4}).empty());
  EXPECT_EQ(ideal_gas_check(IdealGasParams{.gamma = 1.0}).size(), 1U);
  EXPECT_EQ(ideal_gas_check(IdealGasParams{.gamma = 0.4}).size(), 1U);
  EXPECT_EQ(ideal_gas_check(IdealGasParams{.gamma = std::nan("")}).size(), 1U);
}

// ---------------------------------------------------------------- Tait

TEST(TaitEos, PressureAndSoundSpeedAtReferenceState) {
  const TaitParams water{.rho0_kg_m3 = 1000.0, .c0_m_s = 50.0, .gamma = 7.0, .background_pa = 0};
  EXPECT_EQ(tait_pressure(water, 1000.0, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(tait_sound_speed(water, 1000.0, 0.0, 0.0), 50.0);
  // 1 % compression: p = (1000 * 50^2 / 7) (1.01^7 - 1) = 25 740.2... Pa.
  EXPECT_NEAR(tait_pressure(water, 1010.0, 0.0), 1000.0 * 2500.0 / 7.0 * (std::pow(1.01, 7) - 1),
              1e-9);
  const TaitParams with_background{
      .rho0_kg_m3 = 1000.0, .c0_m_s = 50.0, .gamma = 7.0, .background_pa = 2.0e3};
  EXPECT_DOUBLE_EQ(tait_pressure(with_background, 1000.0, 0.0), 2.0e3);
}

TEST(TaitEos, SoundSpeedMatchesFiniteDifference) {
  const TaitParams water{.rho0_kg_m3 = 1000.0, .c0_m_s = 1480.0, .gamma = 7.0, .background_pa = 0};
  for (const Real rho : {950.0, 1000.0, 1030.0}) {
    const Real c = tait_sound_speed(water, rho, 0.0, tait_pressure(water, rho, 0.0));
    EXPECT_NEAR(c, finite_difference_sound_speed(water, rho, 0.0), 1e-6 * c);
  }
}

TEST(TaitEos, CheckFlagsBadConstants) {
  EXPECT_TRUE(tait_check(TaitParams{.rho0_kg_m3 = 1000.0, .c0_m_s = 50.0}).empty());
  const auto problems = tait_check(TaitParams{.rho0_kg_m3 = -1.0, .c0_m_s = 0.0, .gamma = 0.5});
  EXPECT_EQ(problems.size(), 3U) << joined(problems);
  EXPECT_TRUE(any_contains(problems, "rho0_kg_m3"));
  EXPECT_TRUE(any_contains(problems, "c0_m_s"));
  EXPECT_TRUE(any_contains(problems, "gamma"));
}

// ---------------------------------------------------------------- JWL

/// The paper's Table 2 as printed: B = 374700 MPa, R1 = 4015.
JwlParams tnt_jwl_as_printed() {
  JwlParams p = tnt_jwl_standard();
  p.b_pa = 374700e6;
  p.r1 = 4015.0;
  return p;
}

/// p(rho0, e0) = A (1 - w/R1) e^{-R1} + B (1 - w/R2) e^{-R2} + w E0, evaluated by hand.
TEST(JwlEos, InitialPressureOfUnexpandedCharge) {
  const JwlParams standard = tnt_jwl_standard();
  const Real p_standard =
      jwl_pressure(standard, standard.rho0_kg_m3, jwl_specific_energy0(standard));
  // 5.39576 + 0.93098 + 2.10000 GPa.
  EXPECT_NEAR(p_standard, 8.42674e9, 1e4);
  // READING-NOTES: "~8.4 GPa"; that figure is rounded, so 1 %.
  EXPECT_NEAR(p_standard, 8.4e9, 0.01 * 8.4e9);

  const JwlParams llnl = tnt_jwl_llnl();
  // 5.42873 + 0.85496 + 2.10000 GPa.
  EXPECT_NEAR(jwl_pressure(llnl, llnl.rho0_kg_m3, jwl_specific_energy0(llnl)), 8.38370e9, 1e4);

  // As printed, the A term vanishes (e^{-4015}) and the B term is 100x too large:
  // 0 + 93.09768 + 2.10000 GPa. READING-NOTES: "~95 GPa" (1 %).
  const JwlParams printed = tnt_jwl_as_printed();
  const Real p_printed = jwl_pressure(printed, printed.rho0_kg_m3, jwl_specific_energy0(printed));
  EXPECT_NEAR(p_printed, 95.19768e9, 1e4);
  EXPECT_NEAR(p_printed, 95.0e9, 0.01 * 95.0e9);
}

TEST(JwlEos, SpecificEnergyIsVolumetricOverDensity) {
  // Table 2: 3680 kJ/kg; E0 = 6.0 GJ/m^3 / 1630 kg/m^3 = 3681 kJ/kg.
  EXPECT_NEAR(jwl_specific_energy0(tnt_jwl_standard()), 3.68e6, 0.001 * 3.68e6);
}

TEST(JwlEos, ExpandedProductsBehaveAsIdealGasWithGammaOnePlusOmega) {
  // For V >> R1, R2 the exponentials vanish: p -> w rho e, c^2 -> w (w + 1) e.
  const JwlParams tnt = tnt_jwl_standard();
  const Real rho = tnt.rho0_kg_m3 / 100.0;
  const Real e = 2.0e6;
  const Real p = jwl_pressure(tnt, rho, e);
  EXPECT_NEAR(p, tnt.omega * rho * e, 1e-12 * p);
  EXPECT_NEAR(jwl_sound_speed(tnt, rho, e, p), std::sqrt(tnt.omega * (tnt.omega + 1) * e), 1e-6);
}

TEST(JwlEos, SoundSpeedMatchesFiniteDifference) {
  for (const JwlParams& tnt : {tnt_jwl_standard(), tnt_jwl_llnl()}) {
    const Real e0 = jwl_specific_energy0(tnt);
    // Unexpanded, near CJ compression, moderately and strongly expanded, and energy partly
    // spent (as along the release isentrope).
    for (const Real eta : {1.4, 1.0, 0.5, 0.1, 0.01}) {
      for (const Real e : {e0, 0.3 * e0, 2.0 * e0}) {
        const Real rho = eta * tnt.rho0_kg_m3;
        const Real c = jwl_sound_speed(tnt, rho, e, jwl_pressure(tnt, rho, e));
        EXPECT_NEAR(c, finite_difference_sound_speed(tnt, rho, e), 1e-6 * c)
            << "rho/rho0 = " << eta << ", e/e0 = " << e / e0;
      }
    }
  }
}

TEST(JwlEos, SoundSpeedIsFlooredWhenSquareIsNotPositive) {
  const JwlParams tnt = tnt_jwl_standard();
  const Real rho = 0.1 * tnt.rho0_kg_m3;
  const Real e = -1.0e6;  // unphysical, e.g. after an energy error
  const Real c = jwl_sound_speed(tnt, rho, e, jwl_pressure(tnt, rho, e));
  EXPECT_DOUBLE_EQ(c, kJwlSoundSpeedFloorFraction * tnt.d_cj_m_s);
}

TEST(JwlCheck, AcceptsBothTntSets) {
  EXPECT_TRUE(jwl_check(tnt_jwl_standard()).empty()) << joined(jwl_check(tnt_jwl_standard()));
  EXPECT_TRUE(jwl_check(tnt_jwl_llnl()).empty()) << joined(jwl_check(tnt_jwl_llnl()));
}

TEST(JwlCheck, FlagsPrintedR1TypoWithSuggestion) {
  JwlParams p = tnt_jwl_standard();
  p.r1 = 4015.0;
  const auto problems = jwl_check(p);
  ASSERT_EQ(problems.size(), 1U) << joined(problems);
  EXPECT_NE(problems[0].message.find("4015"), std::string::npos) << problems[0].message;
  EXPECT_NE(problems[0].message.find("did you mean ~4.015"), std::string::npos)
      << problems[0].message;
  EXPECT_EQ(problems[0].key, "r1");
}

TEST(JwlCheck, FlagsPrintedBTypoWithSuggestion) {
  JwlParams p = tnt_jwl_standard();
  p.b_pa = 374700e6;  // 374700 MPa as printed
  const auto problems = jwl_check(p);
  ASSERT_EQ(problems.size(), 1U) << joined(problems);
  EXPECT_NE(problems[0].message.find("3.747e+11"), std::string::npos) << problems[0].message;
  EXPECT_NE(problems[0].message.find("did you mean ~3.747e+09"), std::string::npos)
      << problems[0].message;
  EXPECT_EQ(problems[0].key, "b_pa");
}

TEST(JwlCheck, FlagsBothPrintedTypos) {
  const auto problems = jwl_check(tnt_jwl_as_printed());
  EXPECT_EQ(problems.size(), 2U) << joined(problems);
}

TEST(JwlCheck, FlagsR1NotAboveR2) {
  JwlParams p = tnt_jwl_standard();
  p.r1 = 2.5;  // both inside their ranges, but in the wrong order
  p.r2 = 2.8;
  const auto problems = jwl_check(p);
  ASSERT_EQ(problems.size(), 1U) << joined(problems);
  EXPECT_NE(problems[0].message.find("must exceed"), std::string::npos) << problems[0].message;

  // Swapped outright: both out of range, and said to be swapped (no decimal-slip hints).
  p = tnt_jwl_standard();
  std::swap(p.r1, p.r2);
  const auto swapped = jwl_check(p);
  ASSERT_EQ(swapped.size(), 3U) << joined(swapped);
  EXPECT_NE(swapped[2].message.find("swapped"), std::string::npos) << swapped[2].message;
  EXPECT_FALSE(any_contains(swapped, "did you mean")) << joined(swapped);
}

TEST(JwlCheck, FlagsEnergyGivenInKilojoulePerKilogram) {
  JwlParams p = tnt_jwl_standard();
  p.e0_j_m3 = 3680.0;  // Table 2's "3680 kJ/kg" copied verbatim
  const auto problems = jwl_check(p);
  ASSERT_EQ(problems.size(), 1U) << joined(problems);
  EXPECT_NE(problems[0].message.find("5.9984e+09"), std::string::npos) << problems[0].message;
}

TEST(JwlCheck, FlagsDeclaredVelocityInconsistentWithConstants) {
  JwlParams p = tnt_jwl_standard();
  p.d_cj_m_s = 7500.0;  // in range, but the constants give 6930 m/s
  const auto problems = jwl_check(p);
  ASSERT_EQ(problems.size(), 1U) << joined(problems);
  EXPECT_NE(problems[0].message.find("6929"), std::string::npos) << problems[0].message;
}

TEST(JwlCheck, FlagsMixedSets) {
  JwlParams p = tnt_jwl_standard();
  p.e0_j_m3 = tnt_jwl_llnl().e0_j_m3;  // the constants now give D = 7013 m/s
  const auto problems = jwl_check(p);
  ASSERT_EQ(problems.size(), 1U) << joined(problems);
  EXPECT_NE(problems[0].message.find("7013"), std::string::npos) << problems[0].message;
}

TEST(JwlCheck, FlagsUnsetParameters) {
  // A default-constructed set has every constant 0: all eight are reported.
  EXPECT_EQ(jwl_check(JwlParams{}).size(), 8U) << joined(jwl_check(JwlParams{}));
}

// ---------------------------------------------------------------- variant dispatch

TEST(EosVariant, DispatchesToEachLaw) {
  const IdealGasParams gas{.gamma = 1.4};
  const TaitParams water{.rho0_kg_m3 = 1000.0, .c0_m_s = 50.0};
  const JwlParams tnt = tnt_jwl_standard();
  const EosParams laws[] = {gas, water, tnt};
  const Real rho[] = {1.2, 1010.0, 1700.0};
  const Real e[] = {2.0e5, 0.0, 4.0e6};
  const Real p_direct[] = {ideal_gas_pressure(gas, rho[0], e[0]),
                           tait_pressure(water, rho[1], e[1]), jwl_pressure(tnt, rho[2], e[2])};
  const Real c_direct[] = {ideal_gas_sound_speed(gas, rho[0], e[0], p_direct[0]),
                           tait_sound_speed(water, rho[1], e[1], p_direct[1]),
                           jwl_sound_speed(tnt, rho[2], e[2], p_direct[2])};
  for (int i = 0; i < 3; ++i) {
    const Real p = pressure(laws[i], rho[i], e[i]);
    EXPECT_EQ(p, p_direct[i]);
    EXPECT_EQ(sound_speed(laws[i], rho[i], e[i], p), c_direct[i]);
    EXPECT_TRUE(eos_check(laws[i]).empty()) << joined(eos_check(laws[i]));
  }
  EXPECT_FALSE(eos_check(EosParams{IdealGasParams{.gamma = 0.9}}).empty());
}

}  // namespace
}  // namespace crater::materials
