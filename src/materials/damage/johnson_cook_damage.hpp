// Johnson-Cook ductile damage (fracture) model [JC85], with element failure at D >= 1.
//
//   D = \sum \Delta\bar\varepsilon_p / \varepsilon_f                                        [-]
//   \varepsilon_f = [D_1 + D_2 \exp(D_3 \sigma^*)] [1 + D_4 \ln\dot\varepsilon^*] [1 + D_5 T^*]
//   \sigma^* = \sigma_m / \sigma_{vm} = -p / \sigma_{vm}   (stress triaxiality)
// Sign convention: tension positive, p = -tr(\sigma)/3 positive in compression, so \sigma^* > 0
// in tension (uniaxial tension 1/3, equibiaxial 2/3) and < 0 in compression; with the usual
// D_3 < 0 the failure strain falls as the triaxiality rises. \dot\varepsilon^* is the plastic
// strain rate over \dot\varepsilon_0 floored at r_min (as in the flow stress), T^* the
// homologous temperature in [0, 1]. A point with \sigma_{vm} = 0 has \sigma^* = 0 (it accrues
// no plastic strain anyway). If the product is <= 0 (possible for sets with D_1 < 0 at high
// triaxiality) the point fails at once.
//
// References
//   [JC85] G. R. Johnson, W. H. Cook, "Fracture characteristics of three metals subjected to
//          various strains, strain rates, temperatures and pressures", Eng. Fract. Mech. 21
//          (1985) 31-48 (the D_1..D_5 of 4340 steel: 0.05, 3.44, -2.12, 0.002, 0.61).
//   [MJ19] M. Murugesan, D. W. Jung, Materials 12 (2019) 609 (the paper's ref. [40]).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/types.hpp"
#include "materials/strength/stress_tensor.hpp"

namespace crater::materials {

/// Johnson-Cook damage constants D_1..D_5 [-] and the rate/temperature references.
struct JohnsonCookDamageParams {
  Real d1 = 0, d2 = 0, d3 = 0, d4 = 0, d5 = 0;  // D_1..D_5 of the file comment [-]
  Real reference_strain_rate_1_s = 1.0;
  Real min_rate_ratio = 1.0;
  Real room_temperature_k = 293.15;
  Real melt_temperature_k = 1793.0;
};

/// The paper's Table 3 damage constants (the classic 4340-steel set of [JC85]).
inline JohnsonCookDamageParams paper_steel_johnson_cook_damage() {
  return JohnsonCookDamageParams{.d1 = 0.05, .d2 = 3.44, .d3 = -2.12, .d4 = 0.002, .d5 = 0.61};
}

/// Stress triaxiality \sigma^* = \sigma_m / \sigma_{vm} = -p/\sigma_{vm} [-]; 0 when
/// \sigma_{vm} = 0.
inline Real stress_triaxiality(const Mat3& stress) {
  const Real vm = von_mises(stress);
  return vm > 0 ? (stress.trace() / Real(3)) / vm : Real(0);
}

/// Failure strain \varepsilon_f [-]; triaxiality [-], plastic strain rate [1/s], T [K].
/// Returns 0 when the product is not positive (immediate failure).
inline Real johnson_cook_failure_strain(const JohnsonCookDamageParams& p, Real triaxiality,
                                        Real plastic_strain_rate, Real temperature_k) {
  const Real ratio = std::max(plastic_strain_rate / p.reference_strain_rate_1_s, p.min_rate_ratio);
  const Real t_star = std::clamp(
      (temperature_k - p.room_temperature_k) / (p.melt_temperature_k - p.room_temperature_k),
      Real(0), Real(1));
  const Real eps_f = (p.d1 + p.d2 * std::exp(p.d3 * triaxiality)) *
                     (Real(1) + p.d4 * std::log(ratio)) * (Real(1) + p.d5 * t_star);
  return std::max(eps_f, Real(0));
}

/// Damage increment \Delta\bar\varepsilon_p / \varepsilon_f [-] (infinite if \varepsilon_f = 0).
inline Real johnson_cook_damage_increment(const JohnsonCookDamageParams& p,
                                          Real plastic_strain_increment, Real triaxiality,
                                          Real plastic_strain_rate, Real temperature_k) {
  if (!(plastic_strain_increment > 0)) {
    return 0;
  }
  const Real eps_f =
      johnson_cook_failure_strain(p, triaxiality, plastic_strain_rate, temperature_k);
  return eps_f > 0 ? plastic_strain_increment / eps_f : std::numeric_limits<Real>::infinity();
}

/// A point has failed (its element erodes) once D >= 1.
inline bool johnson_cook_failed(Real damage) {
  return damage >= Real(1);
}

}  // namespace crater::materials
