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
#pragma once

#include <variant>
#include <vector>

#include "core/types.hpp"
#include "materials/eos/constant_problem.hpp"
#include "materials/strength/drucker_prager.hpp"
#include "materials/strength/elastic.hpp"
#include "materials/strength/johnson_cook.hpp"
#include "materials/strength/stress_tensor.hpp"

namespace crater::materials {

using StrengthParams = std::variant<ElasticParams, JohnsonCookParams, DruckerPragerParams>;

/// State of a material point carried between steps (unused fields stay at their defaults).
struct MaterialPointState {
  Real plastic_strain = 0;  // equivalent plastic strain [-]
  Real temperature_k = 293.15;
};

/// Result of one stress update.
struct StressUpdate {
  Mat3 stress;                        // \sigma_{n+1} [Pa]
  Real plastic_strain_increment = 0;  // \Delta\bar\varepsilon_p [-]
  Real plastic_work_j_m3 = 0;         // [J/m^3]
  Real temperature_increment_k = 0;   // adiabatic heating [K]
};

inline const ElasticParams& elastic_of(const ElasticParams& law) {
  return law;
}
inline const ElasticParams& elastic_of(const JohnsonCookParams& law) {
  return law.elastic;
}
inline const ElasticParams& elastic_of(const DruckerPragerParams& law) {
  return law.elastic;
}

/// The elastic constants of whichever law `params` holds (wave speed, stable step).
inline const ElasticParams& elastic_of(const StrengthParams& params) {
  return std::visit([](const auto& law) -> const ElasticParams& { return elastic_of(law); },
                    params);
}

inline StressUpdate update_stress_of(const ElasticParams& law, const Mat3& stress,
                                     const Mat3& strain_increment,
                                     const MaterialPointState& /*state*/, Real /*dt*/,
                                     Real /*density*/) {
  return StressUpdate{.stress = stress + elastic_stress_increment(law, strain_increment)};
}

inline StressUpdate update_stress_of(const JohnsonCookParams& law, const Mat3& stress,
                                     const Mat3& strain_increment, const MaterialPointState& state,
                                     Real dt, Real density) {
  const Mat3 trial = stress + elastic_stress_increment(law.elastic, strain_increment);
  const RadialReturn r =
      johnson_cook_radial_return(law, deviator(trial),
                                 JohnsonCookState{.plastic_strain = state.plastic_strain,
                                                  .temperature_k = state.temperature_k},
                                 dt, density);
  return StressUpdate{.stress = r.deviator + (trial.trace() / Real(3)) * Mat3::Identity(),
                      .plastic_strain_increment = r.plastic_strain_increment,
                      .plastic_work_j_m3 = r.plastic_work_j_m3,
                      .temperature_increment_k = r.temperature_increment_k};
}

inline StressUpdate update_stress_of(const DruckerPragerParams& law, const Mat3& stress,
                                     const Mat3& strain_increment,
                                     const MaterialPointState& /*state*/, Real /*dt*/,
                                     Real /*density*/) {
  const DruckerPragerReturn r =
      drucker_prager_return(law, stress + elastic_stress_increment(law.elastic, strain_increment));
  return StressUpdate{.stress = r.stress,
                      .plastic_strain_increment = r.equivalent_plastic_strain_increment,
                      .plastic_work_j_m3 = r.plastic_work_j_m3};
}

/// Problems with the constants of whichever law `params` holds; empty when usable.
inline std::vector<ConstantProblem> strength_check(const StrengthParams& params) {
  struct Checker {
    std::vector<ConstantProblem> operator()(const ElasticParams& law) const {
      return elastic_check(law);
    }
    std::vector<ConstantProblem> operator()(const JohnsonCookParams& law) const {
      return johnson_cook_check(law);
    }
    std::vector<ConstantProblem> operator()(const DruckerPragerParams& law) const {
      return drucker_prager_check(law);
    }
  };
  return std::visit(Checker{}, params);
}

}  // namespace crater::materials
