// Jones-Wilkins-Lee (JWL) equation of state for detonation products.
//
// References
//   [LFC73] E. Lee, M. Finger, W. Collins, "JWL equation of state coefficients for high
//           explosives", LLNL UCID-16189 (1973) (paper ref. [7]).
//   [DC85]  B. M. Dobratz, P. C. Crawford, "LLNL Explosives Handbook", UCRL-52997 Change 2
//           (1985), table of JWL parameters (section 8).
//   [FD79]  W. Fickett, W. C. Davis, "Detonation", University of California Press (1979),
//           ch. 2 (Rayleigh line, Hugoniot, Chapman-Jouguet condition).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/types.hpp"
#include "materials/eos/constant_problem.hpp"

namespace crater::materials {

/// JWL constants. Pressures in Pa, energies per unit *initial* volume in J/m^3.
///   rho0_kg_m3  unreacted explosive density \rho_0
///   a_pa, b_pa  A, B
///   r1, r2      R_1, R_2 [-]
///   omega       Grueneisen coefficient \omega [-]
///   e0_j_m3     detonation energy per unit initial volume E_0 = \rho_0 e_0
///   d_cj_m_s    declared Chapman-Jouguet detonation velocity D
struct JwlParams {
  Real rho0_kg_m3 = 0.0;
  Real a_pa = 0.0;
  Real b_pa = 0.0;
  Real r1 = 0.0;
  Real r2 = 0.0;
  Real omega = 0.0;
  Real e0_j_m3 = 0.0;
  Real d_cj_m_s = 0.0;
};

/// TNT as found in commercial hydrocode material libraries (the paper's Table 2 with its two
/// typos corrected: B = 3747 MPa, R1 = 4.15; E0 = 3680 kJ/kg x 1630 kg/m^3 = 6.0 GJ/m^3).
inline JwlParams tnt_jwl_standard() {
  return JwlParams{.rho0_kg_m3 = 1630.0,
                   .a_pa = 373.8e9,
                   .b_pa = 3.747e9,
                   .r1 = 4.15,
                   .r2 = 0.90,
                   .omega = 0.35,
                   .e0_j_m3 = 6.0e9,
                   .d_cj_m_s = 6930.0};
}

/// TNT from [DC85] (after [LFC73]).
inline JwlParams tnt_jwl_llnl() {
  return JwlParams{.rho0_kg_m3 = 1630.0,
                   .a_pa = 371.2e9,
                   .b_pa = 3.231e9,
                   .r1 = 4.15,
                   .r2 = 0.95,
                   .omega = 0.30,
                   .e0_j_m3 = 7.0e9,
                   .d_cj_m_s = 6930.0};
}

/// Initial specific internal energy of the products e_0 = E_0 / \rho_0 [J/kg].
inline Real jwl_specific_energy0(const JwlParams& params) {
  return params.e0_j_m3 / params.rho0_kg_m3;
}

namespace detail {

/// The two exponential terms of eq. 40 as a function of the relative volume V = \rho_0/\rho:
///   f(V) = A (1 - \omega/(R_1 V)) e^{-R_1 V} + B (1 - \omega/(R_2 V)) e^{-R_2 V}   [Pa].
inline Real jwl_exponential_terms(const JwlParams& params, Real v_rel) {
  const Real w = params.omega;
  return params.a_pa * (Real(1) - w / (params.r1 * v_rel)) * std::exp(-params.r1 * v_rel) +
         params.b_pa * (Real(1) - w / (params.r2 * v_rel)) * std::exp(-params.r2 * v_rel);
}

}  // namespace detail

/// JWL pressure [Pa] (paper eq. 40; [LFC73]):
///   p = A (1 - \omega/(R_1 V)) e^{-R_1 V} + B (1 - \omega/(R_2 V)) e^{-R_2 V} + \omega E / V,
/// with V = \rho_0/\rho and E = \rho_0 e the energy per unit initial volume, so that
///   \omega E / V = \omega \rho e.
/// rho [kg/m^3]; e specific internal energy [J/kg] (e = E_0/\rho_0 in the unexpanded charge).
inline Real jwl_pressure(const JwlParams& params, Real rho, Real e) {
  const Real v_rel = params.rho0_kg_m3 / rho;
  return detail::jwl_exponential_terms(params, v_rel) + params.omega * rho * e;
}

/// Below this fraction of D the JWL sound speed is floored (see jwl_sound_speed).
inline constexpr Real kJwlSoundSpeedFloorFraction = 1e-3;

/// JWL sound speed [m/s], the isentropic derivative of p(\rho, e):
///   c^2 = (\partial p/\partial \rho)_e + (p/\rho^2) (\partial p/\partial e)_\rho,
///   (\partial p/\partial e)_\rho = \omega \rho,
///   (\partial p/\partial \rho)_e = \sum_{i=1,2} (A_i/\rho) e^{-R_i V}
///                                   (R_i V - \omega - \omega/(R_i V)) + \omega e,
/// with (A_1, A_2) = (A, B), V = \rho_0/\rho, hence
///   c^2 = (\partial p/\partial \rho)_e + \omega p / \rho.
/// p must be jwl_pressure(rho, e) [Pa]; it is passed in because the caller already has it.
/// c^2 <= 0 can occur for e < 0 (over-expanded products after energy errors) or far outside the
/// calibrated range; then c = 1e-3 D (about 7 m/s for TNT) is returned, small against any
/// physical product sound speed but positive so the CFL step and artificial viscosity stay
/// finite.
inline Real jwl_sound_speed(const JwlParams& params, Real rho, Real e, Real p) {
  const Real v_rel = params.rho0_kg_m3 / rho;
  const Real w = params.omega;
  auto term = [&](Real amplitude, Real r) {
    const Real rv = r * v_rel;
    return amplitude / rho * std::exp(-rv) * (rv - w - w / rv);
  };
  const Real dp_drho = term(params.a_pa, params.r1) + term(params.b_pa, params.r2) + w * e;
  const Real c2 = dp_drho + w * p / rho;
  const Real floor = kJwlSoundSpeedFloorFraction * params.d_cj_m_s;
  return c2 > floor * floor ? std::sqrt(c2) : floor;
}

/// The Chapman-Jouguet state of a detonation in the unreacted explosive.
struct CjState {
  Real pressure_pa;
  Real density_kg_m3;
  Real particle_velocity_m_s;
  Real detonation_velocity_m_s;
};

/// Chapman-Jouguet point implied by the JWL constants alone ([FD79] ch. 2). This is the
/// consistency check between the JWL constants and the declared D: a published set was fitted
/// to pass through the measured CJ state, so the D computed here must agree with d_cj_m_s.
///
/// Products Hugoniot centred on the unreacted explosive (v_0 = 1/\rho_0, p_0 ~ 0 against GPa,
/// e_0 = E_0/\rho_0 the chemical energy released):
///   e - e_0 = (1/2) (p + p_0) (v_0 - v).
/// JWL is linear in e, p = f(V) + \omega e / v, so the Hugoniot pressure is explicit:
///   p_H(v) = (f(V) + \omega e_0 / v) / (1 - \omega (v_0 - v) / (2 v)),
/// finite for v > \omega v_0 / (2 + \omega).
/// Rayleigh line from (v_0, 0): \rho_0^2 D^2 = p / (v_0 - v). The CJ point is where it is
/// tangent to the Hugoniot, i.e. where D^2(v) = v_0^2 p_H(v)/(v_0 - v) has its minimum on the
/// branch leaving v_0 (D^2 -> infinity as v -> v_0). Mass conservation gives
/// u = D (1 - \rho_0/\rho).
/// Solved by marching v down from v_0 in steps of 1e-3 v_0 until D^2 rises, then golden-section
/// search in the bracket. If the branch ends (p_H <= 0 or the pole of p_H) before D^2 has a
/// minimum, there is no CJ point and all fields are NaN.
inline CjState jwl_cj_state(const JwlParams& params) {
  constexpr Real nan = std::numeric_limits<Real>::quiet_NaN();
  const CjState none{nan, nan, nan, nan};
  const Real w = params.omega;
  const Real e0 = jwl_specific_energy0(params);
  const Real v0 = Real(1) / params.rho0_kg_m3;
  // D^2 as a function of the relative volume V = v/v0; NaN where the branch is not physical.
  auto d2 = [&](Real v_rel) -> Real {
    const Real v = v_rel * v0;
    const Real denominator = Real(1) - w * (v0 - v) / (Real(2) * v);
    if (!(denominator > Real(0))) {
      return nan;
    }
    const Real p = (detail::jwl_exponential_terms(params, v_rel) + w * e0 / v) / denominator;
    if (!(p > Real(0))) {
      return nan;
    }
    return v0 * v0 * p / (v0 - v);
  };

  constexpr Real step = 1e-3;
  Real upper = Real(1);  // bracket [lower, upper] around the minimum
  Real previous = std::numeric_limits<Real>::infinity();
  Real lower = nan;
  for (int k = 1; k < 1000; ++k) {
    const Real v_rel = Real(1) - step * k;
    const Real value = d2(v_rel);
    if (std::isnan(value)) {
      return none;
    }
    if (value > previous) {
      lower = v_rel;
      break;
    }
    previous = value;
    upper = std::min(Real(1) - step * (k - 1), Real(1) - step * 1e-3);
  }
  if (std::isnan(lower)) {
    return none;
  }

  // Golden-section search on [lower, upper]; D^2 is smooth and unimodal there.
  const Real g = Real(0.5) * (std::sqrt(Real(5)) - Real(1));
  Real a = lower;
  Real b = upper;
  Real c = b - g * (b - a);
  Real d = a + g * (b - a);
  Real fc = d2(c);
  Real fd = d2(d);
  while (b - a > Real(1e-13)) {
    if (fc < fd) {
      b = d;
      d = c;
      fd = fc;
      c = b - g * (b - a);
      fc = d2(c);
    } else {
      a = c;
      c = d;
      fc = fd;
      d = a + g * (b - a);
      fd = d2(d);
    }
  }
  const Real v_rel = Real(0.5) * (a + b);
  const Real dcj = std::sqrt(d2(v_rel));
  const Real rho = params.rho0_kg_m3 / v_rel;
  return CjState{
      .pressure_pa = params.rho0_kg_m3 * params.rho0_kg_m3 * dcj * dcj * (v0 - v_rel * v0),
      .density_kg_m3 = rho,
      .particle_velocity_m_s = dcj * (Real(1) - v_rel),
      .detonation_velocity_m_s = dcj};
}

namespace detail {

/// Published range of one JWL constant and a typical value (used to rank typo suggestions).
struct JwlConstantRange {
  const char* name;
  const char* unit;  // with a leading space; empty when dimensionless
  Real low;
  Real high;
  Real typical;
};

inline std::string format_real(Real value) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%.6g", value);
  return buffer;
}

/// A decimal-point or unit-prefix slip: among value * 10^{+-k}, k = 1..6 (divide when the
/// value is too large, multiply when too small), the candidate inside [low, high] closest (in
/// log) to the typical value; NaN when none fits. "Closest to typical" rather than "first in
/// range": for the printed B = 3.747e11 Pa the first in-range candidate would be 3.747e10, the
/// intended value is 3.747e9; for R1 = 4015 both rules give 4.015.
inline Real decimal_slip_suggestion(const JwlConstantRange& range, Real value) {
  if (!(value > Real(0)) || !std::isfinite(value)) {
    return std::numeric_limits<Real>::quiet_NaN();
  }
  Real best = std::numeric_limits<Real>::quiet_NaN();
  Real best_distance = std::numeric_limits<Real>::infinity();
  for (int k = 1; k <= 6; ++k) {
    const Real factor = std::pow(Real(10), value > range.high ? -k : k);
    const Real candidate = value * factor;
    if (candidate < range.low || candidate > range.high) {
      continue;
    }
    const Real distance = std::abs(std::log10(candidate / range.typical));
    if (distance < best_distance) {
      best = candidate;
      best_distance = distance;
    }
  }
  return best;
}

}  // namespace detail

/// Relative mismatch between the CJ velocity implied by the constants and the declared D above
/// which jwl_check complains. Both TNT sets here reproduce their D to 0.01 %, and rounding
/// published constants to 4 digits moves it by ~0.1 %. Mixing sets moves it by 0.4-1.2 % (e.g.
/// the standard TNT set with the LLNL E0: 7013 m/s, +1.2 %), so 1 % catches only the grosser
/// mixes and wrong declared velocities; it is a plausibility test, not a proof of consistency.
inline constexpr Real kJwlCjVelocityTolerance = 0.01;

/// Problems with a JWL set, in words; empty when the set is usable. Each constant must lie in
/// the range spanned by published sets for condensed explosives ([LFC73], [DC85]: from ANFO
/// and emulsions to HMX/PETN, with margin); an out-of-range value that looks like a misplaced
/// decimal point or unit prefix gets a suggestion. When every constant is in range, the CJ
/// velocity implied by the constants (jwl_cj_state) must match the declared D within 2 %.
inline std::vector<ConstantProblem> jwl_check(const JwlParams& params) {
  using detail::format_real;
  constexpr detail::JwlConstantRange r1_range{"r1 (R1)", "", 2.0, 10.0, 4.5};
  constexpr detail::JwlConstantRange r2_range{"r2 (R2)", "", 0.1, 3.0, 1.0};
  auto in = [](const detail::JwlConstantRange& range, Real value) {
    return value >= range.low && value <= range.high;
  };
  const std::array<std::pair<detail::JwlConstantRange, Real>, 8> constants{{
      {{"rho0_kg_m3", " kg/m^3", 500.0, 2500.0, 1600.0}, params.rho0_kg_m3},
      {{"d_cj_m_s", " m/s", 1000.0, 10000.0, 7000.0}, params.d_cj_m_s},
      {{"a_pa (A)", " Pa", 1e9, 2e12, 5e11}, params.a_pa},
      {{"b_pa (B)", " Pa", 1e8, 1e11, 5e9}, params.b_pa},
      {r1_range, params.r1},
      {r2_range, params.r2},
      {{"omega", "", 0.1, 0.6, 0.3}, params.omega},
      {{"e0_j_m3 (E0)", " J/m^3", 1e9, 2e10, 7e9}, params.e0_j_m3},
  }};
  std::vector<ConstantProblem> problems;
  for (const auto& [range, value] : constants) {
    if (std::isfinite(value) && in(range, value)) {
      continue;
    }
    std::string message = std::string("JWL: ") + range.name + " = " + format_real(value) +
                          " is outside the published range [" + format_real(range.low) + ", " +
                          format_real(range.high) + "]" + range.unit +
                          " for condensed explosives (Lee, Finger & Collins 1973; Dobratz & "
                          "Crawford 1985)";
    const std::string_view name(range.name);
    // The paper's Table 2 gives the detonation energy in kJ/kg; E0 is per unit volume.
    const Real from_kj_per_kg = value * Real(1000) * params.rho0_kg_m3;
    const bool energy_per_mass = name.starts_with("e0") && in(range, from_kj_per_kg);
    // R1 and R2 exchanged: both fit once swapped back, so no decimal-slip hint for them.
    const bool swapped_exponents = (name.starts_with("r1") || name.starts_with("r2")) &&
                                   in(r1_range, params.r2) && in(r2_range, params.r1);
    const Real suggestion = detail::decimal_slip_suggestion(range, value);
    if (energy_per_mass) {
      message += "; if " + format_real(value) +
                 " is a specific energy in kJ/kg, E0 = e rho0 = " + format_real(from_kj_per_kg) +
                 " J/m^3";
    } else if (!swapped_exponents && !std::isnan(suggestion)) {
      message += "; did you mean ~" + format_real(suggestion) +
                 " (a misplaced decimal point or unit prefix)?";
    }
    const std::string key(name.substr(0, name.find(' ')));
    problems.push_back({key, message});
  }
  if (params.r1 > 0 && params.r2 > 0 && !(params.r1 > params.r2)) {
    problems.push_back(
        {"r1", "JWL: r1 (R1) = " + format_real(params.r1) +
                   " must exceed r2 (R2) = " + format_real(params.r2) +
                   " (R1 governs the high-pressure term near V = 1, R2 the expanded one; "
                   "swapped constants?)"});
  }
  if (problems.empty()) {
    const CjState cj = jwl_cj_state(params);
    if (std::isnan(cj.detonation_velocity_m_s)) {
      problems.push_back(
          {"",
           "JWL: the constants give no Chapman-Jouguet point (the Rayleigh line from the "
           "unreacted state never touches the products Hugoniot)"});
    } else if (std::abs(cj.detonation_velocity_m_s - params.d_cj_m_s) >
               kJwlCjVelocityTolerance * params.d_cj_m_s) {
      problems.push_back({"d_cj_m_s", "JWL: the constants imply a CJ detonation velocity of " +
                                          format_real(cj.detonation_velocity_m_s) +
                                          " m/s but d_cj_m_s = " + format_real(params.d_cj_m_s) +
                                          " m/s (more than " +
                                          format_real(100 * kJwlCjVelocityTolerance) +
                                          " % apart; constants from different sets mixed?)"});
    }
  }
  return problems;
}

/// The law in the EOS interface (eos.hpp), found by its parameter type.
inline Real eos_pressure_of(const JwlParams& law, Real rho, Real e) {
  return jwl_pressure(law, rho, e);
}
inline Real eos_sound_speed_of(const JwlParams& law, Real rho, Real e, Real p) {
  return jwl_sound_speed(law, rho, e, p);
}
inline std::vector<ConstantProblem> eos_check_of(const JwlParams& law) {
  return jwl_check(law);
}

}  // namespace crater::materials
