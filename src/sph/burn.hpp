// The programmed burn of an explosive SPH part (Wilkins 1964; LS-DYNA's
// *MAT_HIGH_EXPLOSIVE_BURN): a particle's pressure is F p_JWL(rho, e) with the burn fraction
//   F1 = (t - t_light) D / (1.5 dx)       (lighting time: the front reaches the particle)
//   F2 = (1 - V) / (1 - V_CJ), V = rho0/rho (beta burn: compressed to the CJ volume, it burns)
//   F  = min(1, max(F_previous, F1, F2)).
// F never decreases. F2 lets the products' compression light the explosive just ahead of the
// front, which brings the front's pressure closer to P_CJ at a given resolution. Lighting times:
// sph_setup.hpp (lighting_time).
#pragma once

#include <algorithm>
#include <cmath>
#include <variant>

#include "core/types.hpp"
#include "materials/eos/eos.hpp"

namespace crater::sph {

struct ProgrammedBurn {
  bool explosive = false;        // a JWL part burns; any other is lit throughout (F = 1)
  Real detonation_velocity = 0;  // D [m/s]
  Real rho_ref = 0, rho_cj = 0;  // unreacted density rho0 and CJ density, for the beta burn
  bool beta = false;             // F2 on (a CJ state denser than rho0, detonation points)
  Real width = 0;                // distance over which F1 ramps from 0 to 1 [m]

  /// The burn of a part of this EOS and lattice pitch, with or without detonation points.
  static ProgrammedBurn of(const materials::EosParams& eos, Real spacing_m, bool detonations) {
    ProgrammedBurn b;
    if (const auto* jwl = std::get_if<materials::JwlParams>(&eos)) {
      b.explosive = true;
      b.detonation_velocity = jwl->d_cj_m_s;
      b.rho_ref = jwl->rho0_kg_m3;
      b.rho_cj = materials::jwl_cj_state(*jwl).density_kg_m3;
      b.beta = std::isfinite(b.rho_cj) && b.rho_cj > b.rho_ref && detonations;
      b.width = 1.5 * spacing_m;
    }
    return b;
  }

  /// F of a particle lit at t_light, of density rho, burnt to `previous` so far, at time t.
  Real fraction(Real t, Real t_light, Real previous, Real rho) const {
    if (!explosive) return 1;
    const Real f1 = t < t_light ? 0.0 : (t - t_light) * detonation_velocity / (width);
    const Real f2 = beta ? (1 - rho_ref / rho) / (1 - rho_ref / rho_cj) : 0.0;
    return std::min(1.0, std::max({previous, f1, f2}));
  }
};

}  // namespace crater::sph
