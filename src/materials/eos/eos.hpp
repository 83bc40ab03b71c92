// Equations of state p(rho, e): the closed set crater knows, as one std::variant.
//
// e is always the SPECIFIC internal energy [J/kg], rho the density [kg/m^3], p in Pa.
// The functions below dispatch per call and are meant for set-up, checks and tests. Hot loops
// dispatch once per block instead (STYLE habit 1):
//   std::visit([&](const auto& law) { for (...) p[i] = eos_pressure_of(law, rho[i], e[i]); },
//              params);
// where eos_pressure_of / eos_sound_speed_of resolve at compile time to the law's function.
//
// A law is its header (parameters, equations with units and citation, *_check, and its
// overloads eos_pressure_of, eos_sound_speed_of, eos_check_of) plus its alternative in
// EosParams below; the scenario names it through its entry in io/scenario/material_laws.cpp.
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
  return std::visit([](const auto& law) { return eos_check_of(law); }, params);
}

}  // namespace crater::materials
