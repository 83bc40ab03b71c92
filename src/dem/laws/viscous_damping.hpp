// Viscous contact damping from a coefficient of normal restitution e (the damping sub-model of
// the linear and Hertz-Mindlin laws).
//
// References
//   [TTI92] Y. Tsuji, T. Tanaka, T. Ishida, "Lagrangian numerical simulation of plug flow of
//           cohesionless particles in a horizontal pipe", Powder Technol. 71 (1992) 239-250.
//   [AE11]  D. Antypov, J. A. Elliott, "On an analytical solution for the damped Hertzian
//           spring", EPL 94 (2011) 50004.
//   [LIGGGHTS] LIGGGHTS-PUBLIC 3.8, src/normal_model_hertz.h and src/global_properties.h
//           (`betaeff`, `sqrtFiveOverSix`).
#pragma once

#include <cmath>
#include <numbers>

#include "core/types.hpp"

namespace crater::dem {

/// Damping ratio of a linear spring-dashpot with restitution e (paper's damping "from
/// restitution"; the exact inverse of restitution_from_damping_ratio):
///   \zeta = -\ln e / \sqrt{\pi^2 + \ln^2 e}   [-],   e in (0, 1]; e <= 0 gives the limit 1.
/// LIGGGHTS calls \beta = \ln e / \sqrt{\ln^2 e + \pi^2} = -\zeta.
inline Real damping_ratio_from_restitution(Real restitution) {
  if (!(restitution > Real(0))) {
    return Real(1);
  }
  const Real log_e = std::log(restitution);
  return -log_e / std::sqrt(std::numbers::pi * std::numbers::pi + log_e * log_e);
}

/// Restitution of a linear spring-dashpot whose contact ends at zero overlap:
///   e = \exp(-\pi \zeta / \sqrt{1 - \zeta^2})   [-],   0 <= \zeta < 1 (0 for \zeta >= 1).
inline Real restitution_from_damping_ratio(Real damping_ratio) {
  if (!(damping_ratio < Real(1))) {
    return Real(0);
  }
  return std::exp(-std::numbers::pi * damping_ratio /
                  std::sqrt(Real(1) - damping_ratio * damping_ratio));
}

/// Dashpot of a linear spring k [N/m] between bodies of effective mass m* [kg]:
///   c = 2 \zeta \sqrt{k m*}   [N s/m].
inline Real linear_dashpot_coefficient(Real damping_ratio, Real stiffness, Real mass_eff) {
  return Real(2) * damping_ratio * std::sqrt(stiffness * mass_eff);
}

/// \sqrt{5/6}, the factor of [TTI92]'s dashpot as LIGGGHTS writes it.
inline constexpr Real kSqrtFiveSixths = 0.91287092917527685576;

/// Dashpot of a Hertz or Mindlin contact with tangent stiffness S [N/m] (LIGGGHTS
/// `model hertz`, after [TTI92]):
///   \gamma = 2 \sqrt{5/6} \zeta \sqrt{S m*}   [N s/m]
/// (LIGGGHTS: \gamma = -2 \sqrt{5/6} \beta \sqrt{S m*}, \beta = -\zeta). Since S \propto \sqrt{δ},
/// \gamma \propto δ^{1/4}; with the normal tangent stiffness S_n = 2 E* \sqrt{R* δ} and the
/// contact allowed to end at δ = 0 (a slightly attractive force near the end), the restitution
/// of a head-on collision is exactly e and independent of the impact speed [AE11].
inline Real tsuji_dashpot_coefficient(Real damping_ratio, Real tangent_stiffness, Real mass_eff) {
  return Real(2) * kSqrtFiveSixths * damping_ratio * std::sqrt(tangent_stiffness * mass_eff);
}

}  // namespace crater::dem
