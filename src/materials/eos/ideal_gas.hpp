// Ideal (calorically perfect) gas equation of state.
#pragma once

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "materials/eos/constant_problem.hpp"

namespace crater::materials {

/// Parameters of the ideal-gas law. gamma = c_p / c_v [-] (1.4 for air).
struct IdealGasParams {
  Real gamma = 1.4;
};

/// Ideal-gas pressure [Pa] (e.g. Toro 2009, Riemann Solvers, eq. 1.32):
///   p = (\gamma - 1) \rho e,
/// rho [kg/m^3], e specific internal energy [J/kg].
inline Real ideal_gas_pressure(const IdealGasParams& params, Real rho, Real e) {
  return (params.gamma - Real(1)) * rho * e;
}

/// Ideal-gas sound speed [m/s] (Toro 2009, eq. 1.36):
///   c^2 = \gamma p / \rho,
/// with p = ideal_gas_pressure(rho, e) [Pa]. A negative pressure (only reachable through a
/// negative energy, i.e. a numerical error upstream) gives c = 0 instead of NaN.
inline Real ideal_gas_sound_speed(const IdealGasParams& params, Real rho, Real /*e*/, Real p) {
  return std::sqrt(std::max(params.gamma * p / rho, Real(0)));
}

/// Problems with the constants, in words; empty when the set is usable.
inline std::vector<ConstantProblem> ideal_gas_check(const IdealGasParams& params) {
  std::vector<ConstantProblem> problems;
  if (!std::isfinite(params.gamma) || params.gamma <= Real(1)) {
    std::ostringstream os;
    os << "ideal gas: gamma = " << params.gamma
       << " must be a finite number > 1 (gamma = c_p/c_v; 1.4 for air, 5/3 for a monatomic gas)";
    problems.push_back({"gamma", os.str()});
  }
  return problems;
}

/// The law in the EOS interface (eos.hpp), found by its parameter type.
inline Real eos_pressure_of(const IdealGasParams& law, Real rho, Real e) {
  return ideal_gas_pressure(law, rho, e);
}
inline Real eos_sound_speed_of(const IdealGasParams& law, Real rho, Real e, Real p) {
  return ideal_gas_sound_speed(law, rho, e, p);
}
inline std::vector<ConstantProblem> eos_check_of(const IdealGasParams& law) {
  return ideal_gas_check(law);
}

}  // namespace crater::materials
