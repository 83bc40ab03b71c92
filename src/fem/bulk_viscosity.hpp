// Linear + quadratic bulk (artificial) viscosity for shocks in solids, and the stable step it
// implies, as LS-DYNA defines them [LSD] after von Neumann & Richtmyer [vNR50] and Landshoff.
//
//   q = \rho l (C_0 l \dot\varepsilon_{kk}^2 - C_1 c \dot\varepsilon_{kk})  if \dot\varepsilon_{kk}
//   < 0, q = 0 otherwise                                                                   [Pa]
// added to the pressure (\sigma - q I) in the force computation, never stored in the stress.
// C_0 = 1.5 (quadratic), C_1 = 0.06 (linear) are LS-DYNA's defaults; l = V^{1/D} the element
// size; \dot\varepsilon_{kk} = tr d the volumetric strain rate.
// Stable step with the viscosity [LSD]:
//   \Delta t_e = L_e / (Q + \sqrt{Q^2 + c^2}),   Q = C_1 c + C_0 L_e |\dot\varepsilon_{kk}|
// (Q = 0 in expansion), L_e the characteristic length (element_geometry.hpp).
//
// References
//   [vNR50] J. von Neumann, R. D. Richtmyer, "A method for the numerical calculation of
//           hydrodynamic shocks", J. Appl. Phys. 21 (1950) 232-237.
//   [LSD]   LS-DYNA Theory Manual (LSTC/Ansys), "Bulk viscosity" and "Time step control".
#pragma once

#include <cmath>

#include "core/types.hpp"

namespace crater::fem {

/// Coefficients of the bulk viscosity [-].
struct BulkViscosityParams {
  Real quadratic = 1.5;  // C_0
  Real linear = 0.06;    // C_1
};

/// Bulk viscosity pressure q [Pa] (>= 0; zero in expansion). density [kg/m^3], wave_speed c
/// [m/s], size l [m], volumetric strain rate tr d [1/s].
inline Real bulk_viscosity_pressure(const BulkViscosityParams& p, Real density, Real wave_speed,
                                    Real size, Real volumetric_strain_rate) {
  if (volumetric_strain_rate >= 0) {
    return 0;
  }
  return density * size *
         (p.quadratic * size * volumetric_strain_rate * volumetric_strain_rate -
          p.linear * wave_speed * volumetric_strain_rate);
}

/// Stable step of one element [s] with the bulk viscosity (header comment).
inline Real stable_element_step(const BulkViscosityParams& p, Real characteristic_length,
                                Real wave_speed, Real volumetric_strain_rate) {
  const Real q = volumetric_strain_rate < 0
                     ? p.linear * wave_speed +
                           p.quadratic * characteristic_length * std::abs(volumetric_strain_rate)
                     : Real(0);
  return characteristic_length / (q + std::sqrt(q * q + wave_speed * wave_speed));
}

}  // namespace crater::fem
