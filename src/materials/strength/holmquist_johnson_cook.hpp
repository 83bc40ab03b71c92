// Holmquist-Johnson-Cook (HJC) concrete [HJC93] (LS-DYNA *MAT_JOHNSON_HOLMQUIST_CONCRETE,
// *MAT_111) as a material-point law: a compaction equation of state, a pressure- and
// rate-dependent strength surface softened by damage, and damage from plastic shear and pore
// crushing. In scenarios as `model = "holmquist_johnson_cook"` for FEM parts: StrengthParams
// holds it as a HolmquistJohnsonCookLaw (the constants with their derived EOS constants,
// computed once), and the FEM element loop keeps HjcState per element (fem/explicit_solid.cpp).
//
// Signs as stress_tensor.hpp: tension positive, p = -tr(\sigma)/3 > 0 in compression;
// \mu = \rho/\rho_0 - 1 > 0 in compression. P^* = p/f_c, T^* = T/f_c.
//
// Equation of state [HJC93 Fig. 3], K_e = P_c/\mu_c, \mu_{max} the largest \mu reached:
//   region I, \mu_{max} <= \mu_c:              p = K_e \mu  (loading = unloading)
//   region II, \mu_c < \mu_{max} < \mu_{pl}:
//     loading (\mu >= \mu_{max}):  p = P_c + (P_l - P_c)(\mu - \mu_c)/(\mu_{pl} - \mu_c)
//     unloading, reloading:        p = p(\mu_{max}) - \bar K (\mu_{max} - \mu),
//                                  \bar K = (1 - F) K_e + F K_1,
//                                  F = (\mu_{max} - \mu_c)/(\mu_{pl} - \mu_c)
//   region III (fully dense), \mu_{max} >= \mu_{pl}, loading and unloading:
//     p = K_1\bar\mu + K_2\bar\mu^2 + K_3\bar\mu^3 (\bar\mu >= 0),  p = K_1\bar\mu (\bar\mu < 0),
//     \bar\mu = (\mu - \mu_l)/(1 + \mu_l)
//   tension cutoff: p >= -T (1 - D).                                                       [Pa]
// \mu_l (mu_lock) is [HJC93]'s locking strain \rho_{grain}/\rho_0 - 1, where the fully dense curve
// has zero pressure. The compression at P_l, \mu_{pl} ("mu_plock" of [HJC93] Fig. 3), is not an
// input: it is where the fully dense curve reaches P_l, \mu_{pl} = \mu_l + (1 + \mu_l) x_l with
// K_1 x_l + K_2 x_l^2 + K_3 x_l^3 = P_l (0.110554 for the 48 MPa set). Reading mu_lock as the end
// of the crush line would drop the loading pressure from P_l to 0 there.
// Plastic volumetric strain (the zero-pressure intercept of the unloading line):
//   \mu_p = 0 (I),  \mu_{max} - p(\mu_{max})/\bar K (II),  its value at \mu_{pl} (III: voids
//   closed).
//
// Strength [HJC93; tensile branch as LS-DYNA, after IMP and OR below], \sigma^* = \sigma_y/f_c:
//   P^* >= 0:  \sigma^* = [A(1 - D) + B P^{*N}] (1 + C \ln\dot\varepsilon^*)
//   P^* <  0:  \sigma^* = A (1 + P^*/T^*)(1 - D) (1 + C \ln\dot\varepsilon^*)  (>= 0)
//   \sigma^* <= S_{max};  \dot\varepsilon^* = \max(\dot\varepsilon/\dot\varepsilon_0, 1)
// (no rate effect below the reference rate, as LS-DYNA and OpenRadioss; \dot\varepsilon is the
// equivalent deviatoric strain rate \sqrt{2/3\,\dot e:\dot e} of the step).
//
// Damage [HJC93]:
//   \Delta D = (\Delta\varepsilon_p + \Delta\mu_p) / \varepsilon_f,
//   \varepsilon_f = \max(EF_{min}, D_1 (P^* + T^*)^{D_2}),   D <= 1.
//
// Stress update (update_stress_of), one material point over one step:
//   1. \mu = \rho_{n+1}/\rho_0 - 1; p from the EOS with \mu_{max,n} and D_n; new \mu_{max}, \mu_p.
//   2. s^{tr} = dev(\sigma_n) + 2G dev(\Delta\varepsilon),  q^{tr} = \sqrt{3/2\, s^{tr}:s^{tr}}.
//   3. \sigma_y = f_c \sigma^*(p, D_n, \dot\varepsilon).  If q^{tr} > \sigma_y: s =
//   (\sigma_y/q^{tr})
//      s^{tr}, \Delta\varepsilon_p = (q^{tr} - \sigma_y)/(3G) (exact: the surface does not depend
//      on \varepsilon_p).
//   4. D_{n+1} = \min(1, D_n + \Delta D) with \varepsilon_f at p_{n+1};  \sigma_{n+1} = s - p I.
//
// References
//   [HJC93] T. J. Holmquist, G. R. Johnson, W. H. Cook, "A computational constitutive model for
//           concrete subjected to large strains, high strain rates, and high pressures", Proc.
//           14th Int. Symp. Ballistics, Quebec (1993) 591-600.
//   [LSD]   LS-DYNA Keyword User's Manual, Vol. II, *MAT_JOHNSON_HOLMQUIST_CONCRETE (*MAT_111).
//   [IMP]   IMPETUS Afea Solver manual, *MAT_HJC_CONCRETE (the tensile branch above).
//   [OR]    OpenRadioss /MAT/LAW126, engine/source/materials/mat/mat126/sigeps126.F90.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "core/types.hpp"
#include "materials/eos/constant_problem.hpp"
#include "materials/strength/elastic.hpp"
#include "materials/strength/stress_tensor.hpp"

namespace crater::materials {

/// HJC constants (SI). A, B, C, N, S_max, EF_min, D_1, D_2, \mu_c, \mu_l are dimensionless.
///   rho0_kg_m3         initial density \rho_0 [kg/m^3]
///   shear_modulus_pa   G [Pa]
///   a, b, n            normalized cohesive strength A, pressure hardening B and exponent N
///   c                  strain-rate coefficient C
///   fc_pa, t_pa        quasi-static uniaxial compressive strength f_c, max. tensile pressure T
///   s_max              normalized maximum strength S_max
///   eps0_per_s         reference strain rate \dot\varepsilon_0 [1/s]
///   ef_min             minimum plastic strain to fracture EF_min
///   d1, d2             damage constants D_1, D_2
///   p_crush_pa, mu_crush   crushing point P_c, \mu_c (end of the elastic region)
///   k1_pa, k2_pa, k3_pa    fully dense pressure constants K_1, K_2, K_3
///   p_lock_pa, mu_lock     locking pressure P_l and locking strain \mu_l (see the header)
struct HolmquistJohnsonCookParams {
  Real rho0_kg_m3 = 0;
  Real shear_modulus_pa = 0;
  Real a = 0;
  Real b = 0;
  Real c = 0;
  Real n = 1;
  Real fc_pa = 0;
  Real t_pa = 0;
  Real s_max = 0;
  Real eps0_per_s = 1;
  Real ef_min = 0;
  Real d1 = 0;
  Real d2 = 1;
  Real p_crush_pa = 0;
  Real mu_crush = 0;
  Real k1_pa = 0;
  Real k2_pa = 0;
  Real k3_pa = 0;
  Real p_lock_pa = 0;
  Real mu_lock = 0;
};

/// The 48 MPa concrete of [HJC93] (its Table of constants, as LS-DYNA's *MAT_111 example).
/// The 1993 proceedings were not at hand; all 20 values were confirmed against third-party
/// copies: an LS-DYNA *MAT_111 card in SI units in a public LS-DYNA-to-OpenRadioss converter's
/// tests, and the HJC example of a public GDEM (blkdyn/pdyna) manual (identical values).
inline HolmquistJohnsonCookParams holmquist_johnson_cook_48mpa_concrete() {
  return HolmquistJohnsonCookParams{.rho0_kg_m3 = 2440.0,
                                    .shear_modulus_pa = 14.86e9,
                                    .a = 0.79,
                                    .b = 1.60,
                                    .c = 0.007,
                                    .n = 0.61,
                                    .fc_pa = 48e6,
                                    .t_pa = 4e6,
                                    .s_max = 7.0,
                                    .eps0_per_s = 1.0,
                                    .ef_min = 0.01,
                                    .d1 = 0.04,
                                    .d2 = 1.0,
                                    .p_crush_pa = 16e6,
                                    .mu_crush = 0.001,
                                    .k1_pa = 85e9,
                                    .k2_pa = -171e9,
                                    .k3_pa = 208e9,
                                    .p_lock_pa = 800e6,
                                    .mu_lock = 0.1};
}

/// State of a material point carried between steps.
struct HjcState {
  Real damage = 0;                     // D [-], in [0, 1]
  Real mu_max = 0;                     // largest \mu = \rho/\rho_0 - 1 reached [-]
  Real plastic_volumetric_strain = 0;  // \mu_p [-]
  Real plastic_strain = 0;             // equivalent (deviatoric) plastic strain \varepsilon_p [-]
};

/// Constants of the EOS derived once from the parameters.
struct HjcEosConstants {
  Real k_elastic_pa = 0;  // K_e = P_c/\mu_c [Pa]
  Real mu_plock = 0;      // \mu_{pl}, compression at P_l (NaN: the dense curve never reaches P_l)
  Real k_crush_pa = 0;    // (P_l - P_c)/(\mu_{pl} - \mu_c) [Pa]
};

/// Fully dense pressure [Pa]: K_1\bar\mu + K_2\bar\mu^2 + K_3\bar\mu^3, or K_1\bar\mu in
/// tension, \bar\mu = (\mu - \mu_l)/(1 + \mu_l).
inline Real hjc_dense_pressure(const HolmquistJohnsonCookParams& p, Real mu) {
  const Real x = (mu - p.mu_lock) / (Real(1) + p.mu_lock);
  return x < 0 ? p.k1_pa * x : x * (p.k1_pa + x * (p.k2_pa + x * p.k3_pa));
}

/// x_l > 0 with K_1 x + K_2 x^2 + K_3 x^3 = P_l, by bracketing and bisection to round-off;
/// NaN when the cubic does not reach P_l (e.g. K_1 <= 0).
inline Real hjc_dense_lock_strain(const HolmquistJohnsonCookParams& p) {
  constexpr Real nan = std::numeric_limits<Real>::quiet_NaN();
  auto cubic = [&p](Real x) { return x * (p.k1_pa + x * (p.k2_pa + x * p.k3_pa)); };
  if (!(p.k1_pa > 0) || !(p.p_lock_pa > 0)) {
    return nan;
  }
  Real lo = 0;
  Real hi = p.p_lock_pa / p.k1_pa;
  for (int k = 0; cubic(hi) < p.p_lock_pa; ++k) {
    if (k >= 64 || !std::isfinite(hi)) {
      return nan;
    }
    lo = hi;
    hi *= 2;
  }
  for (int it = 0; it < 200 && hi - lo > 2 * std::numeric_limits<Real>::epsilon() * hi; ++it) {
    const Real mid = Real(0.5) * (lo + hi);
    if (cubic(mid) < p.p_lock_pa) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return Real(0.5) * (lo + hi);
}

inline HjcEosConstants hjc_eos_constants(const HolmquistJohnsonCookParams& p) {
  HjcEosConstants c;
  c.k_elastic_pa = p.p_crush_pa / p.mu_crush;
  c.mu_plock = p.mu_lock + (Real(1) + p.mu_lock) * hjc_dense_lock_strain(p);
  c.k_crush_pa = (p.p_lock_pa - p.p_crush_pa) / (c.mu_plock - p.mu_crush);
  return c;
}

/// Pressure on the loading curve (\mu = \mu_{max}) [Pa], regions I, II, III.
inline Real hjc_loading_pressure(const HolmquistJohnsonCookParams& p, const HjcEosConstants& c,
                                 Real mu) {
  if (mu <= p.mu_crush) {
    return c.k_elastic_pa * mu;
  }
  if (mu < c.mu_plock) {
    return p.p_crush_pa + c.k_crush_pa * (mu - p.mu_crush);
  }
  return hjc_dense_pressure(p, mu);
}

/// Unloading modulus \bar K = (1 - F) K_e + F K_1 of region II [Pa] (K_e below \mu_c).
inline Real hjc_unloading_modulus(const HolmquistJohnsonCookParams& p, const HjcEosConstants& c,
                                  Real mu_max) {
  const Real f = std::clamp((mu_max - p.mu_crush) / (c.mu_plock - p.mu_crush), Real(0), Real(1));
  return (Real(1) - f) * c.k_elastic_pa + f * p.k1_pa;
}

/// HJC pressure [Pa] at \mu [-] for a point whose largest compression so far is mu_max [-]
/// (\mu > mu_max loads along the curve), with the tensile cutoff -T(1 - D).
inline Real hjc_pressure(const HolmquistJohnsonCookParams& p, const HjcEosConstants& c, Real mu,
                         Real mu_max, Real damage) {
  const Real peak = std::max(mu, mu_max);
  Real pressure = 0;
  if (peak <= p.mu_crush || mu >= peak) {
    pressure = hjc_loading_pressure(p, c, mu);
  } else if (peak < c.mu_plock) {
    pressure = hjc_loading_pressure(p, c, peak) - hjc_unloading_modulus(p, c, peak) * (peak - mu);
  } else {
    pressure = hjc_dense_pressure(p, mu);
  }
  return std::max(pressure, -p.t_pa * (Real(1) - damage));
}

inline Real hjc_pressure(const HolmquistJohnsonCookParams& p, Real mu, Real mu_max, Real damage) {
  return hjc_pressure(p, hjc_eos_constants(p), mu, mu_max, damage);
}

/// Plastic volumetric strain \mu_p [-] after a largest compression mu_max (header comment).
inline Real hjc_plastic_volumetric_strain(const HolmquistJohnsonCookParams& p,
                                          const HjcEosConstants& c, Real mu_max) {
  if (mu_max <= p.mu_crush) {
    return 0;
  }
  const Real peak = std::min(mu_max, c.mu_plock);
  return peak - hjc_loading_pressure(p, c, peak) / hjc_unloading_modulus(p, c, peak);
}

/// Rate factor 1 + C \ln\dot\varepsilon^*, \dot\varepsilon^* floored at 1 [-]; rate [1/s].
inline Real hjc_rate_factor(const HolmquistJohnsonCookParams& p, Real strain_rate) {
  const Real ratio = strain_rate / p.eps0_per_s;
  return ratio > 1 ? Real(1) + p.c * std::log(ratio) : Real(1);
}

/// Normalized equivalent strength \sigma^* = \sigma_y/f_c [-] at pressure [Pa], damage [-] and
/// strain rate [1/s] (header comment).
inline Real hjc_normalized_strength(const HolmquistJohnsonCookParams& p, Real pressure_pa,
                                    Real damage, Real strain_rate) {
  const Real p_star = pressure_pa / p.fc_pa;
  const Real intact = Real(1) - damage;
  const Real s = p_star >= 0 ? p.a * intact + p.b * std::pow(p_star, p.n)
                             : std::max(Real(0), p.a * (Real(1) + pressure_pa / p.t_pa) * intact);
  return std::min(p.s_max, s * hjc_rate_factor(p, strain_rate));
}

/// Plastic strain to fracture \varepsilon_f = max(EF_min, D_1 (P^* + T^*)^{D_2}) [-].
inline Real hjc_fracture_strain(const HolmquistJohnsonCookParams& p, Real pressure_pa) {
  const Real sum = (pressure_pa + p.t_pa) / p.fc_pa;
  return std::max(p.ef_min, sum > 0 ? p.d1 * std::pow(sum, p.d2) : Real(0));
}

/// Damage increment (\Delta\varepsilon_p + \Delta\mu_p)/\varepsilon_f [-] (negative increments
/// count as zero).
inline Real hjc_damage_increment(const HolmquistJohnsonCookParams& p, Real plastic_strain_increment,
                                 Real plastic_volumetric_strain_increment, Real pressure_pa) {
  const Real strain = std::max(plastic_strain_increment, Real(0)) +
                      std::max(plastic_volumetric_strain_increment, Real(0));
  return strain > 0 ? strain / hjc_fracture_strain(p, pressure_pa) : Real(0);
}

/// Result of one HJC stress update.
struct HjcStressUpdate {
  Mat3 stress;                                   // \sigma_{n+1} [Pa]
  HjcState state;                                // at the end of the step
  Real pressure_pa = 0;                          // p_{n+1} [Pa]
  Real yield_stress_pa = 0;                      // \sigma_y of the return [Pa]
  Real plastic_strain_increment = 0;             // \Delta\varepsilon_p [-]
  Real plastic_volumetric_strain_increment = 0;  // \Delta\mu_p [-]
  Real damage_increment = 0;                     // D_{n+1} - D_n [-]
  Real plastic_work_j_m3 = 0;                    // \sigma_y \Delta\varepsilon_p [J/m^3]
};

/// One step of the HJC material point (header comment, steps 1-4): stress at the start of the
/// step (already rotated) [Pa], strain increment [-], state, step dt [s] (dt <= 0: quasi-static,
/// no rate effect) and the density at the end of the step [kg/m^3]; eos = hjc_eos_constants(law),
/// computed once by the caller (it bisects).
inline HjcStressUpdate update_stress_of(const HolmquistJohnsonCookParams& law,
                                        const HjcEosConstants& eos, const Mat3& stress,
                                        const Mat3& strain_increment, const HjcState& state,
                                        Real dt, Real density) {
  HjcStressUpdate out;
  out.state = state;
  // 1. Pressure, compaction history and plastic volumetric strain.
  const Real mu = density / law.rho0_kg_m3 - Real(1);
  out.pressure_pa = hjc_pressure(law, eos, mu, state.mu_max, state.damage);
  out.state.mu_max = std::max(state.mu_max, mu);
  const Real mu_p = hjc_plastic_volumetric_strain(law, eos, out.state.mu_max);
  out.plastic_volumetric_strain_increment =
      std::max(Real(0), mu_p - state.plastic_volumetric_strain);
  out.state.plastic_volumetric_strain = std::max(mu_p, state.plastic_volumetric_strain);
  // 2-3. Deviatoric trial and radial return to sigma* f_c.
  const Real g = law.shear_modulus_pa;
  const Mat3 de = deviator(strain_increment);
  const Mat3 s_trial = deviator(stress) + Real(2) * g * de;
  const Real q_trial = std::sqrt(Real(3) * second_invariant(s_trial));
  const Real rate =
      dt > 0 ? std::sqrt(Real(2) / Real(3) * de.cwiseProduct(de).sum()) / dt : Real(0);
  out.yield_stress_pa =
      law.fc_pa * hjc_normalized_strength(law, out.pressure_pa, state.damage, rate);
  Mat3 s = s_trial;
  if (q_trial > out.yield_stress_pa) {
    s = (out.yield_stress_pa / q_trial) * s_trial;
    out.plastic_strain_increment = (q_trial - out.yield_stress_pa) / (Real(3) * g);
    out.plastic_work_j_m3 = out.yield_stress_pa * out.plastic_strain_increment;
  }
  out.state.plastic_strain += out.plastic_strain_increment;
  // 4. Damage, with the fracture strain at the new pressure.
  const Real d_new =
      std::min(Real(1), state.damage + hjc_damage_increment(law, out.plastic_strain_increment,
                                                            out.plastic_volumetric_strain_increment,
                                                            out.pressure_pa));
  out.damage_increment = d_new - state.damage;
  out.state.damage = d_new;
  out.stress = s - out.pressure_pa * Mat3::Identity();
  return out;
}

/// The same, deriving the EOS constants on each call (tests, single points).
inline HjcStressUpdate update_stress_of(const HolmquistJohnsonCookParams& law, const Mat3& stress,
                                        const Mat3& strain_increment, const HjcState& state,
                                        Real dt, Real density) {
  return update_stress_of(law, hjc_eos_constants(law), stress, strain_increment, state, dt,
                          density);
}

/// Problems with the constants, in words; empty when usable.
inline std::vector<ConstantProblem> holmquist_johnson_cook_check(
    const HolmquistJohnsonCookParams& p) {
  std::vector<ConstantProblem> problems;
  auto complain = [&problems](const char* key, Real value, const char* expected) {
    std::ostringstream os;
    os << "Holmquist-Johnson-Cook: " << key << " = " << value << " " << expected;
    problems.push_back({key, os.str()});
  };
  auto positive = [&complain](const char* key, Real value, const char* unit) {
    if (!(value > 0) || !std::isfinite(value)) {
      complain(key, value, unit);
    }
  };
  positive("rho0_kg_m3", p.rho0_kg_m3, "must be positive [kg/m^3]");
  positive("shear_modulus_pa", p.shear_modulus_pa, "must be positive [Pa]");
  positive("a", p.a, "must be positive");
  positive("n", p.n, "must be positive");
  positive("fc_pa", p.fc_pa, "must be positive [Pa]");
  positive("t_pa", p.t_pa, "must be positive [Pa] (the tensile pressure limit)");
  positive("s_max", p.s_max, "must be positive");
  positive("eps0_per_s", p.eps0_per_s, "must be positive [1/s]");
  positive("ef_min", p.ef_min, "must be positive (it bounds the damage increment)");
  positive("p_crush_pa", p.p_crush_pa, "must be positive [Pa]");
  positive("mu_crush", p.mu_crush, "must be positive");
  positive("k1_pa", p.k1_pa, "must be positive [Pa]");
  if (!(p.b >= 0)) {
    complain("b", p.b, "must be >= 0");
  }
  if (!(p.c >= 0)) {
    complain("c", p.c, "must be >= 0");
  }
  if (!(p.d1 >= 0)) {
    complain("d1", p.d1, "must be >= 0");
  }
  if (!(p.d2 >= 0)) {
    complain("d2", p.d2, "must be >= 0");
  }
  if (!(p.p_lock_pa > p.p_crush_pa)) {
    complain("p_lock_pa", p.p_lock_pa, "must exceed p_crush_pa [Pa]");
  }
  if (!(p.mu_lock > p.mu_crush)) {
    complain("mu_lock", p.mu_lock, "must exceed mu_crush");
  }
  if (!problems.empty()) {
    return problems;
  }
  // The fully dense curve must rise monotonically from 0 to P_l: its slope
  // K_1 + 2 K_2 x + 3 K_3 x^2 positive on [0, x_l] (ends and, if inside, the vertex).
  const Real x_l = hjc_dense_lock_strain(p);
  auto slope = [&p](Real x) { return p.k1_pa + x * (Real(2) * p.k2_pa + Real(3) * p.k3_pa * x); };
  const Real vertex = p.k3_pa > 0 ? -p.k2_pa / (Real(3) * p.k3_pa) : Real(0);
  if (std::isnan(x_l) || !(slope(x_l) > 0) ||
      (vertex > 0 && vertex < x_l && !(slope(vertex) > 0))) {
    complain("k2_pa", p.k2_pa,
             "with k1_pa and k3_pa gives a fully dense curve that does not rise monotonically to "
             "p_lock_pa");
  }
  return problems;
}

inline std::vector<ConstantProblem> strength_check_of(const HolmquistJohnsonCookParams& law) {
  return holmquist_johnson_cook_check(law);
}

// ---- The law as FEM parts use it (an alternative of StrengthParams, strength.hpp) ------------

/// The constants with what is derived from them once per material: the EOS constants (the
/// bisection for \mu_{pl}) and two sets of elastic constants, both with the shear modulus G:
///   elastic: bulk modulus K_{max} = \max(K_e, K_{crush}, K_1), the stiffest slope of the EOS
///            below the cubic's own rise (region II unloads with \bar K in [K_e, K_1], loads
///            with K_{crush} = (P_l - P_c)/(\mu_{pl} - \mu_c); region III starts at slope
///            K_1/(1 + \mu_l)). The stable step, contact stiffness and surface springs use it:
///            conservative for every state (the element loop adds the cubic's tangent and the
///            (1 + \mu) of dp/d\rho, hjc_wave_bulk_modulus).
///   at_rest: bulk modulus K_e = P_c/\mu_c, the material at rest (impedance of non-reflecting
///            boundaries: K_{max} would reflect part of an incoming elastic wave).
/// E = 9KG/(3K + G), \nu = (3K - 2G)/(2(3K + G)).
struct HolmquistJohnsonCookLaw {
  HolmquistJohnsonCookParams params;
  HjcEosConstants eos;
  Real max_bulk_modulus_pa = 0;  // K_{max} [Pa]
  ElasticParams elastic;
  ElasticParams at_rest;
};

/// Elastic constants from a bulk and a shear modulus [Pa].
inline ElasticParams hjc_elastic_from(Real bulk_pa, Real shear_pa) {
  return ElasticParams{
      .youngs_modulus_pa = Real(9) * bulk_pa * shear_pa / (Real(3) * bulk_pa + shear_pa),
      .poisson_ratio =
          (Real(3) * bulk_pa - Real(2) * shear_pa) / (Real(2) * (Real(3) * bulk_pa + shear_pa))};
}

inline HolmquistJohnsonCookLaw holmquist_johnson_cook_law(const HolmquistJohnsonCookParams& p) {
  HolmquistJohnsonCookLaw law;
  law.params = p;
  law.eos = hjc_eos_constants(p);
  law.max_bulk_modulus_pa = std::max({law.eos.k_elastic_pa, law.eos.k_crush_pa, p.k1_pa});
  law.elastic = hjc_elastic_from(law.max_bulk_modulus_pa, p.shear_modulus_pa);
  law.at_rest = hjc_elastic_from(law.eos.k_elastic_pa, p.shear_modulus_pa);
  return law;
}

/// Bulk modulus of the dilatational wave speed [Pa] at compression \mu [-], bounding every state
/// a point at \mu can be in: c^2 = dp/d\rho + 4G/(3\rho) = ((1 + \mu) dp/d\mu + 4G/3)/\rho, so
///   K_{wave} = (1 + \max(\mu, 0)) \max(K_{max}, dp/d\mu|_{dense}(\mu)),
///   dp/d\mu|_{dense} = (K_1 + 2 K_2 \bar\mu + 3 K_3 \bar\mu^2)/(1 + \mu_l) (\bar\mu > 0).
/// The cubic's slope passes K_1 only at large compression (\bar\mu > 0.55, 29 GPa, for the
/// 48 MPa set); below that K_{wave} = (1 + \mu) K_{max}.
inline Real hjc_wave_bulk_modulus(const HolmquistJohnsonCookLaw& law, Real mu) {
  const HolmquistJohnsonCookParams& p = law.params;
  const Real x = (mu - p.mu_lock) / (Real(1) + p.mu_lock);
  const Real dense =
      x > 0 ? (p.k1_pa + x * (Real(2) * p.k2_pa + Real(3) * p.k3_pa * x)) / (Real(1) + p.mu_lock)
            : Real(0);
  return (Real(1) + std::max(mu, Real(0))) * std::max(law.max_bulk_modulus_pa, dense);
}

inline const ElasticParams& elastic_of(const HolmquistJohnsonCookLaw& law) {
  return law.elastic;
}

inline std::vector<ConstantProblem> strength_check_of(const HolmquistJohnsonCookLaw& law) {
  return holmquist_johnson_cook_check(law.params);
}

}  // namespace crater::materials
