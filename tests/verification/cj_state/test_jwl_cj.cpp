// Verification: the Chapman-Jouguet state implied by the JWL constants of TNT.
//
// Reference (computed by nobody here): the measured CJ state of TNT at rho0 = 1630 kg/m^3,
// Dobratz & Crawford 1985, LLNL Explosives Handbook (UCRL-52997 Change 2), TNT entry:
//   D = 6930 m/s, P_CJ = 21.0 GPa,
// and from the jump conditions rho0 D = rho (D - u), P = rho0 D u:
//   u_CJ = P/(rho0 D) = 1859 m/s, rho_CJ = rho0 D/(D - u) = 2228 kg/m^3.
// Both JWL sets were fitted to pass through this state, so jwl_cj_state (Hugoniot + tangent
// Rayleigh line, from the EOS alone) must reproduce it. Tolerances are the reference's
// precision plus the fit's: D 1.5 %, P 5 %, rho and u 3 %.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "materials/eos/jwl.hpp"

namespace crater::materials {
namespace {

constexpr Real kDReference = 6930.0;    // m/s
constexpr Real kPReference = 21.0e9;    // Pa
constexpr Real kRhoReference = 2228.0;  // kg/m^3
constexpr Real kUReference = 1859.0;    // m/s

struct NamedSet {
  std::string name;
  JwlParams params;
};

class JwlCjState : public ::testing::TestWithParam<NamedSet> {};

TEST_P(JwlCjState, MatchesHandbookState) {
  const JwlParams& tnt = GetParam().params;
  const CjState cj = jwl_cj_state(tnt);
  RecordProperty("D_m_s", std::to_string(cj.detonation_velocity_m_s));
  RecordProperty("P_Pa", std::to_string(cj.pressure_pa));
  RecordProperty("rho_kg_m3", std::to_string(cj.density_kg_m3));
  RecordProperty("u_m_s", std::to_string(cj.particle_velocity_m_s));
  EXPECT_NEAR(cj.detonation_velocity_m_s, kDReference, 0.015 * kDReference);
  EXPECT_NEAR(cj.pressure_pa, kPReference, 0.05 * kPReference);
  EXPECT_NEAR(cj.density_kg_m3, kRhoReference, 0.03 * kRhoReference);
  EXPECT_NEAR(cj.particle_velocity_m_s, kUReference, 0.03 * kUReference);
}

// The state returned satisfies the Rankine-Hugoniot jump conditions it was built from.
TEST_P(JwlCjState, SatisfiesJumpConditions) {
  const JwlParams& tnt = GetParam().params;
  const CjState cj = jwl_cj_state(tnt);
  const Real rho0 = tnt.rho0_kg_m3;
  const Real d = cj.detonation_velocity_m_s;
  const Real u = cj.particle_velocity_m_s;
  // Mass: rho0 D = rho (D - u).  Momentum: p = rho0 D u.
  EXPECT_NEAR(rho0 * d, cj.density_kg_m3 * (d - u), 1e-9 * rho0 * d);
  EXPECT_NEAR(cj.pressure_pa, rho0 * d * u, 1e-9 * cj.pressure_pa);
  // Energy: e = e0 + p (v0 - v) / 2 must reproduce p through the EOS.
  const Real e =
      jwl_specific_energy0(tnt) + 0.5 * cj.pressure_pa * (1.0 / rho0 - 1.0 / cj.density_kg_m3);
  EXPECT_NEAR(jwl_pressure(tnt, cj.density_kg_m3, e), cj.pressure_pa, 1e-9 * cj.pressure_pa);
}

// The CJ condition: the flow behind the front is sonic, D = u + c (Fickett & Davis 1979,
// ch. 2). jwl_sound_speed is independent of the tangency search, so this checks both.
TEST_P(JwlCjState, FlowIsSonicBehindFront) {
  const JwlParams& tnt = GetParam().params;
  const CjState cj = jwl_cj_state(tnt);
  const Real e = jwl_specific_energy0(tnt) +
                 0.5 * cj.pressure_pa * (1.0 / tnt.rho0_kg_m3 - 1.0 / cj.density_kg_m3);
  const Real c = jwl_sound_speed(tnt, cj.density_kg_m3, e, cj.pressure_pa);
  EXPECT_NEAR(cj.particle_velocity_m_s + c, cj.detonation_velocity_m_s,
              1e-5 * cj.detonation_velocity_m_s);
}

INSTANTIATE_TEST_SUITE_P(Tnt, JwlCjState,
                         ::testing::Values(NamedSet{"standard", tnt_jwl_standard()},
                                           NamedSet{"llnl", tnt_jwl_llnl()}),
                         [](const ::testing::TestParamInfo<NamedSet>& param_info) {
                           return param_info.param.name;
                         });

// The paper's Table 2 as printed (B = 374700 MPa, R1 = 4015): the Hugoniot pressure falls to
// zero before the Rayleigh line can touch it, so there is no CJ point at all.
TEST(JwlCjStatePrintedTable, HasNoChapmanJouguetPoint) {
  JwlParams printed = tnt_jwl_standard();
  printed.b_pa = 374700e6;
  printed.r1 = 4015.0;
  EXPECT_TRUE(std::isnan(jwl_cj_state(printed).detonation_velocity_m_s));
}

}  // namespace
}  // namespace crater::materials
