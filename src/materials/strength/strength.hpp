// Strength laws: the closed set crater knows, as one std::variant, and the one stress update
// every law provides.
//
// update_stress_of(law, stress, strain_increment, state, dt, density) takes the stress at the
// start of the step already rotated by the objective rate (fem/kinematics.hpp) and the strain
// increment \Delta\varepsilon = d \Delta t, and returns the stress at the end of the step.
// Every law here is hypoelastic: the elastic trial is
//   \sigma^{tr} = \sigma_n + \lambda tr(\Delta\varepsilon) I + 2\mu \Delta\varepsilon
// followed by the law's return (none, J2 radial return, Drucker-Prager cone/apex). For
// Johnson-Cook the pressure stays elastic (K tr \Delta\varepsilon increments); an EOS for the
// pressure can be slotted in later without touching the deviatoric return.
//
// As for EOSs, hot loops dispatch once per block:
//   std::visit([&](const auto& law) { for (...) update_stress_of(law, ...); }, params);
//
// A law is its header (parameters, return with units and citation, *_check, and its overloads
// elastic_of, update_stress_of, strength_check_of; the state and result types are
// stress_update.hpp's) plus its alternative in StrengthParams below; the scenario names it
// through its entry in io/scenario/material_laws.cpp.
#pragma once

#include <variant>
#include <vector>

#include "core/types.hpp"
#include "materials/eos/constant_problem.hpp"
#include "materials/strength/drucker_prager.hpp"
#include "materials/strength/elastic.hpp"
#include "materials/strength/holmquist_johnson_cook.hpp"
#include "materials/strength/johnson_cook.hpp"
#include "materials/strength/stress_tensor.hpp"
#include "materials/strength/stress_update.hpp"

namespace crater::materials {

// HolmquistJohnsonCookLaw carries its own state (HjcState): the FEM element loop treats it
// apart (fem/explicit_solid.cpp); the others share MaterialPointState.
using StrengthParams =
    std::variant<ElasticParams, JohnsonCookParams, DruckerPragerParams, HolmquistJohnsonCookLaw>;

/// The elastic constants of whichever law `params` holds (wave speed, stable step).
inline const ElasticParams& elastic_of(const StrengthParams& params) {
  return std::visit([](const auto& law) -> const ElasticParams& { return elastic_of(law); },
                    params);
}

/// The elastic constants of the material at rest: the impedance of non-reflecting boundaries.
/// Those of elastic_of for every law but HJC, whose elastic_of is its stiffest state.
inline ElasticParams at_rest_elastic_of(const StrengthParams& params) {
  if (const auto* hjc = std::get_if<HolmquistJohnsonCookLaw>(&params)) return hjc->at_rest;
  return elastic_of(params);
}

/// Problems with the constants of whichever law `params` holds; empty when usable.
inline std::vector<ConstantProblem> strength_check(const StrengthParams& params) {
  return std::visit([](const auto& law) { return strength_check_of(law); }, params);
}

}  // namespace crater::materials
