// Rate-dependent friction angle of the paper's sand (§III-C, after its ref. [42]):
//   \varphi_{dyn} = \varphi_s (1 + \beta \log_{10}(\dot\varepsilon / \dot\varepsilon_0)),
//   \mu_{dyn} = \tan \varphi_{dyn},   \varphi_s = \arctan \mu,
// \beta = 0.05, \dot\varepsilon_0 = 1/s. Applied per contact: the pair loop replaces the law's
// friction coefficient \mu by \mu_{dyn} (the Coulomb limit of tangential_history.hpp).
//
// Strain rate. The paper (an LS-DYNA continuum-style statement) does not say which strain rate a
// contact sees. Here it is the rate at which the pair's centre distance changes, relative to
// that distance:
//   \dot\varepsilon = |v_n| / (R_1 + R_2)   [1/s]
// (v_n the normal relative velocity at the contact, contact_geometry.hpp). Against a wall pass
// R_2 = 0: |v_n| / R_1, the rate of change of the grain's distance to the wall relative to that
// distance. It is a per-contact, per-step estimate, so \mu_{dyn} follows the local loading
// rate; it is zero for pure sliding or rolling.
//
// Only strengthening: for \dot\varepsilon <= \dot\varepsilon_0 the logarithm would be negative
// and lower the friction below its static value (and diverge as \dot\varepsilon -> 0, e.g. for
// grains at rest), so there \varphi_{dyn} = \varphi_s: the factor \beta \log_{10} is clamped to
// >= 0. \varphi_{dyn} is also capped at 89° so that \tan stays finite; with \varphi_s = 40° the
// cap would need \dot\varepsilon ~ 10^{24} /s, far beyond any blast.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/types.hpp"

namespace crater::dem {

/// Rate dependence of one material pair. Build with rate_dependent_friction().
struct RateDependentFriction {
  Real static_friction = 0;          // \mu [-]
  Real static_angle_rad = 0;         // \varphi_s = atan(\mu) [rad]
  Real beta = 0.05;                  // \beta [-]
  Real reference_strain_rate = 1.0;  // \dot\varepsilon_0 [1/s]
};

/// From the static friction coefficient \mu; \beta and \dot\varepsilon_0 default to the paper's.
inline RateDependentFriction rate_dependent_friction(Real static_friction, Real beta = 0.05,
                                                     Real reference_strain_rate = 1.0) {
  return RateDependentFriction{.static_friction = static_friction,
                               .static_angle_rad = std::atan(static_friction),
                               .beta = beta,
                               .reference_strain_rate = reference_strain_rate};
}

/// \dot\varepsilon = |v_n| / (R_1 + R_2) [1/s]; v_n [m/s], radii [m] (a wall: r2 = 0).
inline Real contact_strain_rate(Real normal_velocity, Real r1, Real r2) {
  return std::abs(normal_velocity) / (r1 + r2);
}

/// Upper bound of \varphi_{dyn}: 89° [rad].
inline constexpr Real kMaxDynamicFrictionAngle = 89.0 * std::numbers::pi / 180.0;

/// \varphi_{dyn} [rad] at strain rate \dot\varepsilon [1/s] (\varphi_s for rates <=
/// \dot\varepsilon_0).
inline Real dynamic_friction_angle(const RateDependentFriction& f, Real strain_rate) {
  if (!(strain_rate > f.reference_strain_rate)) {
    return f.static_angle_rad;
  }
  const Real factor = Real(1) + f.beta * std::log10(strain_rate / f.reference_strain_rate);
  return std::min(f.static_angle_rad * factor, kMaxDynamicFrictionAngle);
}

/// \mu_{dyn} = tan \varphi_{dyn} [-]; exactly \mu for rates <= \dot\varepsilon_0.
inline Real dynamic_friction_coefficient(const RateDependentFriction& f, Real strain_rate) {
  if (!(strain_rate > f.reference_strain_rate)) {
    return f.static_friction;
  }
  return std::tan(dynamic_friction_angle(f, strain_rate));
}

}  // namespace crater::dem
