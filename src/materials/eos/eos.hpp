// Equations of state p(rho, e): the closed set crater knows, as one std::variant.
//
// e is always the SPECIFIC internal energy [J/kg], rho the density [kg/m^3], p in Pa.
// The functions below dispatch per call and are meant for set-up, checks and tests. Hot loops
// dispatch once per block instead (STYLE habit 1):
//   std::visit([&](const auto& law) { for (...) p[i] = eos_pressure_of(law, rho[i], e[i]); },
//              params);
// where eos_pressure_of / eos_sound_speed_of resolve at compile time to the law's function.
#pragma once

#include <string>
#include <variant>
#include <vector>

#include "core/types.hpp"
#include "materials/eos/ideal_gas.hpp"
#include "materials/eos/jwl.hpp"
#include "materials/eos/tait.hpp"

namespace crater::materials {

using EosParams = std::variant<IdealGasParams, TaitParams, JwlParams>;

/// Overload set naming each law's pressure [Pa] by its parameter type (resolved statically).
inline Real eos_pressure_of(const IdealGasParams& law, Real rho, Real e) {
  return ideal_gas_pressure(law, rho, e);
}
inline Real eos_pressure_of(const TaitParams& law, Real rho, Real e) {
  return tait_pressure(law, rho, e);
}
inline Real eos_pressure_of(const JwlParams& law, Real rho, Real e) {
  return jwl_pressure(law, rho, e);
}

/// Overload set naming each law's sound speed [m/s]; p = that law's pressure at (rho, e).
inline Real eos_sound_speed_of(const IdealGasParams& law, Real rho, Real e, Real p) {
  return ideal_gas_sound_speed(law, rho, e, p);
}
inline Real eos_sound_speed_of(const TaitParams& law, Real rho, Real e, Real p) {
  return tait_sound_speed(law, rho, e, p);
}
inline Real eos_sound_speed_of(const JwlParams& law, Real rho, Real e, Real p) {
  return jwl_sound_speed(law, rho, e, p);
}

/// Pressure [Pa] of whichever law `params` holds.
inline Real pressure(const EosParams& params, Real rho, Real e) {
  return std::visit([&](const auto& law) { return eos_pressure_of(law, rho, e); }, params);
}

/// Sound speed [m/s] of whichever law `params` holds; p = pressure(params, rho, e) [Pa].
inline Real sound_speed(const EosParams& params, Real rho, Real e, Real p) {
  return std::visit([&](const auto& law) { return eos_sound_speed_of(law, rho, e, p); }, params);
}

/// Problems with the constants of whichever law `params` holds; empty when usable.
inline std::vector<ConstantProblem> eos_check(const EosParams& params) {
  struct Checker {
    std::vector<ConstantProblem> operator()(const IdealGasParams& law) const {
      return ideal_gas_check(law);
    }
    std::vector<ConstantProblem> operator()(const TaitParams& law) const { return tait_check(law); }
    std::vector<ConstantProblem> operator()(const JwlParams& law) const { return jwl_check(law); }
  };
  return std::visit(Checker{}, params);
}

}  // namespace crater::materials
