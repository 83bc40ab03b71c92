// What every strength law's stress update takes and gives (strength.hpp): the state of a
// material point carried between steps and the result of one update.
#pragma once

#include "core/types.hpp"
#include "materials/strength/stress_tensor.hpp"

namespace crater::materials {

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

}  // namespace crater::materials
