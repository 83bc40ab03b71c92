// Tait equation of state for weakly compressible SPH ("artificial compressibility").
#pragma once

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "materials/eos/constant_problem.hpp"

namespace crater::materials {

/// Parameters of the Tait law.
///   rho0_kg_m3     reference density \rho_0 [kg/m^3]
///   c0_m_s         reference sound speed c_0 [m/s]; the paper writes B = 100 \rho_0 v_max^2 /
///                  \gamma, i.e. c_0 = 10 v_max (Mach <= 0.1, density error <= ~1 %)
///   gamma          exponent [-], 7 for water (Monaghan 1994; Batchelor 1967)
///   background_pa  background pressure added to p [Pa]
struct TaitParams {
  Real rho0_kg_m3 = 0.0;
  Real c0_m_s = 0.0;
  Real gamma = 7.0;
  Real background_pa = 0.0;
};

/// Tait stiffness B = \rho_0 c_0^2 / \gamma [Pa].
inline Real tait_stiffness(const TaitParams& params) {
  return params.rho0_kg_m3 * params.c0_m_s * params.c0_m_s / params.gamma;
}

/// Tait pressure [Pa] (paper eq. 35, written with the reference sound speed c_0; Monaghan
/// 1994, J. Comput. Phys. 110, 399):
///   p = B [(\rho/\rho_0)^\gamma - 1] + p_b,   B = \rho_0 c_0^2 / \gamma,
/// rho [kg/m^3]. The energy e [J/kg] does not enter (barotropic law).
inline Real tait_pressure(const TaitParams& params, Real rho, Real /*e*/) {
  return tait_stiffness(params) * (std::pow(rho / params.rho0_kg_m3, params.gamma) - Real(1)) +
         params.background_pa;
}

/// Tait sound speed [m/s], exact for the barotropic law:
///   c^2 = dp/d\rho = c_0^2 (\rho/\rho_0)^{\gamma - 1}.
inline Real tait_sound_speed(const TaitParams& params, Real rho, Real /*e*/, Real /*p*/) {
  return params.c0_m_s * std::sqrt(std::pow(rho / params.rho0_kg_m3, params.gamma - Real(1)));
}

/// Problems with the constants, in words; empty when the set is usable.
inline std::vector<ConstantProblem> tait_check(const TaitParams& params) {
  std::vector<ConstantProblem> problems;
  auto complain = [&problems](const char* name, Real value, const char* expected) {
    std::ostringstream os;
    os << "Tait: " << name << " = " << value << " " << expected;
    problems.push_back({name, os.str()});
  };
  if (!std::isfinite(params.rho0_kg_m3) || params.rho0_kg_m3 <= Real(0)) {
    complain("rho0_kg_m3", params.rho0_kg_m3, "must be a positive density [kg/m^3]");
  }
  if (!std::isfinite(params.c0_m_s) || params.c0_m_s <= Real(0)) {
    complain("c0_m_s", params.c0_m_s,
             "must be a positive sound speed [m/s] (usually 10x the largest expected speed)");
  }
  if (!std::isfinite(params.gamma) || params.gamma < Real(1)) {
    complain("gamma", params.gamma, "must be a finite number >= 1 (7 for water)");
  }
  if (!std::isfinite(params.background_pa) || params.background_pa < Real(0)) {
    complain("background_pa", params.background_pa,
             "must be a finite, non-negative pressure [Pa] (it exists to keep p > 0)");
  }
  return problems;
}

/// The law in the EOS interface (eos.hpp), found by its parameter type.
inline Real eos_pressure_of(const TaitParams& law, Real rho, Real e) {
  return tait_pressure(law, rho, e);
}
inline Real eos_sound_speed_of(const TaitParams& law, Real rho, Real e, Real p) {
  return tait_sound_speed(law, rho, e, p);
}
inline std::vector<ConstantProblem> eos_check_of(const TaitParams& law) {
  return tait_check(law);
}

}  // namespace crater::materials
