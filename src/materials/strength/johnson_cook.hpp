// Johnson-Cook flow stress (paper eq. 41) with J2 radial return, for metals (the steel plate).
//
// Flow stress [JC83]:
//   \sigma_y = (A + B \bar\varepsilon_p^n)(1 + C \ln \dot\varepsilon^*)(1 - T^{*m})      [Pa]
//   \dot\varepsilon^* = \max(\dot{\bar\varepsilon}_p / \dot\varepsilon_0, r_{min}),
//   T^* = (T - T_{room}) / (T_{melt} - T_{room}) clamped to [0, 1].
// The rate term uses the equivalent PLASTIC strain rate, as in [JC83] and the paper. Below the
// reference rate the ratio is floored at r_min (default 1: no rate effect below
// \dot\varepsilon_0, as Abaqus does; the paper's literal eq. 41 would soften the metal below
// the reference rate, which r_min < 1 reproduces while 1 + C ln r_min > 0).
//
// Radial return (J2 flow theory, associative, isotropic hardening; [SH98] §3.3, box 3.2):
//   trial deviator s^{tr} = s_n(rotated) + 2\mu \Delta e,   q^{tr} = \sqrt{3/2\, s^{tr}:s^{tr}}
//   if q^{tr} <= \sigma_y(\bar\varepsilon_p, rate floor): elastic.
//   else solve for \Delta\bar\varepsilon_p > 0 (scalar Newton, in ln of it above the rate
//   floor, safeguarded by bisection):
//     q^{tr} - 3\mu \Delta\bar\varepsilon_p
//         = \sigma_y(\bar\varepsilon_p + \Delta\bar\varepsilon_p,\ \Delta\bar\varepsilon_p/\Delta
//         t)
//     s_{n+1} = (1 - 3\mu\Delta\bar\varepsilon_p / q^{tr})\, s^{tr}
// The rate in the consistency condition is the plastic strain rate of the step itself, so the
// returned stress lies exactly on eq. 41 at that rate (implicit in the rate, as LS-DYNA's
// viscoplastic option VP = 1). The pressure is not touched here (hypoelastic bulk response or
// an EOS, the caller's choice).
//
// Plastic work per unit volume \Delta W_p = \sigma_y \Delta\bar\varepsilon_p [J/m^3]. Adiabatic
// heating (optional, [JC83]): \Delta T = \chi \Delta W_p / (\rho c_p), Taylor-Quinney
// \chi = 0.9. The temperature used in \sigma_y is the one at the start of the step (explicit in
// T). The paper switches thermal softening off (T^* = 0, §III-B); so does the default here.
//
// References
//   [JC83] G. R. Johnson, W. H. Cook, "A constitutive model and data for metals subjected to
//          large strains, high strain rates and high temperatures", Proc. 7th Int. Symp.
//          Ballistics, The Hague (1983) 541-547.
//   [JC85] G. R. Johnson, W. H. Cook, "Fracture characteristics of three metals subjected to
//          various strains, strain rates, temperatures and pressures", Eng. Fract. Mech. 21
//          (1985) 31-48.
//   [SH98] J. C. Simo, T. J. R. Hughes, "Computational Inelasticity", Springer (1998), §3.3.
//   [MJ19] M. Murugesan, D. W. Jung, Materials 12 (2019) 609 (the paper's ref. [40], Table 3).
#pragma once

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "core/types.hpp"
#include "materials/eos/constant_problem.hpp"
#include "materials/strength/elastic.hpp"
#include "materials/strength/stress_tensor.hpp"
#include "materials/strength/stress_update.hpp"

namespace crater::materials {

/// Johnson-Cook strength constants (SI).
///   a_pa, b_pa, n            A [Pa], B [Pa], hardening exponent n [-]
///   c                        strain-rate coefficient C [-]
///   m                        thermal softening exponent m [-]
///   reference_strain_rate    \dot\varepsilon_0 [1/s]
///   min_rate_ratio           floor r_min of \dot\varepsilon^* [-] (1: no effect below ref.)
///   room/melt temperature    T_room, T_melt [K]
///   thermal_softening        use (1 - T^{*m}) and adiabatic heating; off in the paper
///   taylor_quinney           fraction \chi of plastic work turned into heat [-]
///   specific_heat_j_kg_k     c_p [J/(kg K)]
struct JohnsonCookParams {
  ElasticParams elastic;
  Real a_pa = 0;
  Real b_pa = 0;
  Real n = 1;
  Real c = 0;
  Real m = 1;
  Real reference_strain_rate_1_s = 1.0;
  Real min_rate_ratio = 1.0;
  Real room_temperature_k = 293.15;
  Real melt_temperature_k = 1793.0;
  bool thermal_softening = false;
  Real taylor_quinney = 0.9;
  Real specific_heat_j_kg_k = 486.0;
};

/// The paper's Table 3 ("AISI-1045", after [MJ19]) with E = 200 GPa, \nu = 0.3, and the
/// paper's \dot\varepsilon_0 = 1/s. Thermal softening off, as in the paper; the melting point
/// (1793 K) and c_p (486 J/(kg K)) are generic carbon-steel values for when it is switched on.
inline JohnsonCookParams paper_steel_johnson_cook() {
  return JohnsonCookParams{.elastic = steel_elastic(),
                           .a_pa = 50.103e6,
                           .b_pa = 176.091e6,
                           .n = 0.5176,
                           .c = 0.095,
                           .m = 0.6622};
}

/// Homologous temperature T^* = (T - T_room)/(T_melt - T_room), clamped to [0, 1].
inline Real johnson_cook_homologous_temperature(const JohnsonCookParams& p, Real temperature_k) {
  const Real t =
      (temperature_k - p.room_temperature_k) / (p.melt_temperature_k - p.room_temperature_k);
  return std::clamp(t, Real(0), Real(1));
}

/// Rate factor 1 + C \ln \dot\varepsilon^*, \dot\varepsilon^* floored at r_min [-].
inline Real johnson_cook_rate_factor(const JohnsonCookParams& p, Real plastic_strain_rate) {
  const Real ratio = std::max(plastic_strain_rate / p.reference_strain_rate_1_s, p.min_rate_ratio);
  return Real(1) + p.c * std::log(ratio);
}

/// Thermal factor 1 - T^{*m} (1 when thermal softening is off) [-].
inline Real johnson_cook_thermal_factor(const JohnsonCookParams& p, Real temperature_k) {
  if (!p.thermal_softening) {
    return Real(1);
  }
  const Real t = johnson_cook_homologous_temperature(p, temperature_k);
  return t > 0 ? Real(1) - std::pow(t, p.m) : Real(1);
}

/// Johnson-Cook flow stress \sigma_y [Pa] (paper eq. 41): equivalent plastic strain [-],
/// equivalent plastic strain rate [1/s], temperature [K].
inline Real johnson_cook_flow_stress(const JohnsonCookParams& p, Real plastic_strain,
                                     Real plastic_strain_rate, Real temperature_k) {
  const Real hardening = p.a_pa + p.b_pa * std::pow(std::max(plastic_strain, Real(0)), p.n);
  return hardening * johnson_cook_rate_factor(p, plastic_strain_rate) *
         johnson_cook_thermal_factor(p, temperature_k);
}

/// State carried by a material point between steps.
struct JohnsonCookState {
  Real plastic_strain = 0;  // equivalent plastic strain \bar\varepsilon_p [-]
  Real temperature_k = 293.15;
};

/// Outcome of one radial return.
struct RadialReturn {
  Mat3 deviator;                      // s_{n+1} [Pa]
  Real plastic_strain_increment = 0;  // \Delta\bar\varepsilon_p [-]
  Real plastic_work_j_m3 = 0;         // \sigma_y \Delta\bar\varepsilon_p [J/m^3]
  Real temperature_increment_k = 0;   // \chi \Delta W_p / (\rho c_p) if heating is on [K]
  Real flow_stress_pa = 0;            // \sigma_y at the end of the step [Pa]
  bool yielded = false;
};

/// Iteration limits of the scalar return (Newton with bisection safeguard). The tolerance is on
/// the consistency residual relative to q^{tr}; 1e-14 is a few ulps of the stresses involved.
inline constexpr int kJohnsonCookMaxIterations = 200;
inline constexpr Real kJohnsonCookTolerance = 1e-14;

/// J2 radial return onto the Johnson-Cook surface (see the header comment). trial_deviator is
/// s_n (already rotated) + 2\mu \Delta e [Pa]; dt the step [s] (rate = \Delta\bar\varepsilon_p /
/// dt; dt <= 0 means quasi-static: rate factor at its floor); density [kg/m^3] for heating.
inline RadialReturn johnson_cook_radial_return(const JohnsonCookParams& p,
                                               const Mat3& trial_deviator,
                                               const JohnsonCookState& state, Real dt,
                                               Real density) {
  RadialReturn out;
  out.deviator = trial_deviator;
  const Real mu = shear_modulus(p.elastic);
  const Real q_trial = std::sqrt(Real(3) * second_invariant(trial_deviator));
  const Real eps0 = state.plastic_strain;
  const Real thermal = johnson_cook_thermal_factor(p, state.temperature_k);
  // sigma_y(eps0 + x, x / dt) (eq. 41 at the step's start temperature) and its slope in x, with
  // one log per evaluation (and a pow only off the series below): the FEM step's innermost loop.
  struct Flow {
    Real stress = 0;
    Real slope = 0;
  };
  // (eps0 + x)^n: the iterates' x is mostly tiny against a strained element's eps0, and then
  // eps0^n (1 + u)^n, u = x / eps0, is the binomial series to u^4 (for |u| <= 1e-3 the first
  // term left out, |C(n, 5)| u^5 <= 0.04e-15 for 0 < n <= 1, is below round-off): one pow per
  // element instead of one per iterate.
  const Real eps0_n = eps0 > 0 ? std::pow(eps0, p.n) : Real(0);
  const Real c1 = p.n, c2 = c1 * (p.n - 1) / 2, c3 = c2 * (p.n - 2) / 3, c4 = c3 * (p.n - 3) / 4;
  auto power_n = [&](Real eps, Real x) {
    if (eps0 > 0 && std::abs(x) <= Real(1e-3) * eps0) {
      const Real u = x / eps0;
      return eps0_n * (1 + u * (c1 + u * (c2 + u * (c3 + u * c4))));
    }
    return std::pow(eps, p.n);
  };
  const Real log_floor = std::log(p.min_rate_ratio);
  auto flow_at = [&](Real x) {
    const Real eps = std::max(eps0 + x, Real(0));
    const Real eps_n = power_n(eps, x);
    const Real hardening = p.a_pa + p.b_pa * eps_n;
    const Real rate_ratio = dt > 0 ? x / dt / p.reference_strain_rate_1_s : Real(0);
    const bool rate_active = rate_ratio > p.min_rate_ratio;
    const Real rate_factor = Real(1) + p.c * (rate_active ? std::log(rate_ratio) : log_floor);
    Flow f;
    f.stress = hardening * rate_factor * thermal;
    // d/dx [B eps^n] = B n eps^n / eps; d/dx [1 + C ln(x / dt / eps_dot0)] = C / x.
    Real d = eps > 0 ? p.b_pa * p.n * (eps_n / eps) * rate_factor : Real(0);
    if (rate_active) {
      d += hardening * p.c / x;
    }
    f.slope = d * thermal;
    return f;
  };
  // Residual r(x) = q_tr - 3 mu x - sigma_y(eps0 + x, x/dt): decreasing and convex in x.
  const Real r0 = q_trial - flow_at(Real(0)).stress;
  out.flow_stress_pa = q_trial - r0;
  if (r0 <= 0 || thermal <= 0) {
    if (thermal <= 0) {  // molten: no deviatoric strength
      out.deviator.setZero();
      out.yielded = q_trial > 0;
      out.plastic_strain_increment = q_trial / (Real(3) * mu);
      out.flow_stress_pa = 0;
    }
    return out;
  }
  // Bracket: r(0) > 0, r(q_tr / 3 mu) = -sigma_y < 0. First guess: the perfectly plastic
  // return r0 / 3 mu (exact without hardening and rate, right of the root otherwise).
  Real lo = 0;
  Real hi = q_trial / (Real(3) * mu);
  Real x = r0 / (Real(3) * mu);
  for (int it = 0; it < kJohnsonCookMaxIterations; ++it) {
    const Flow f = flow_at(x);
    const Real r = q_trial - Real(3) * mu * x - f.stress;
    if (std::abs(r) <= kJohnsonCookTolerance * q_trial) {
      break;
    }
    if (r > 0) {
      lo = x;
    } else {
      hi = x;
    }
    // Newton; above the rate floor's kink (x > dt eps_dot0 r_min) the term C ln x dominates the
    // slope (C sigma_y / x is ~200 x 3 mu at the kink for the paper's steel at dt = 9e-8 s), so
    // the step is taken in ln x there: x <- x exp(-r / (x dr/dx)). Half the iterations.
    const Real slope = -Real(3) * mu - f.slope;
    const bool rate_active = dt > 0 && x / dt / p.reference_strain_rate_1_s > p.min_rate_ratio;
    Real next = rate_active ? x * std::exp(-r / (x * slope)) : x - r / slope;
    if (!(next > lo && next < hi) || !std::isfinite(next)) {
      next = Real(0.5) * (lo + hi);
    }
    if (next == x) {
      break;
    }
    x = next;
  }
  out.yielded = true;
  out.plastic_strain_increment = x;
  const Real q_new = q_trial - Real(3) * mu * x;
  out.deviator = (q_new / q_trial) * trial_deviator;
  out.flow_stress_pa = q_new;
  out.plastic_work_j_m3 = q_new * x;
  if (p.thermal_softening && density > 0) {
    out.temperature_increment_k =
        p.taylor_quinney * out.plastic_work_j_m3 / (density * p.specific_heat_j_kg_k);
  }
  return out;
}

/// Problems with the constants, in words; empty when usable.
inline std::vector<ConstantProblem> johnson_cook_check(const JohnsonCookParams& p) {
  std::vector<ConstantProblem> problems = elastic_check(p.elastic);
  auto complain = [&problems](const char* key, Real value, const char* expected) {
    std::ostringstream os;
    os << "Johnson-Cook: " << key << " = " << value << " " << expected;
    problems.push_back({key, os.str()});
  };
  if (!(p.a_pa > 0)) {
    complain("a_pa", p.a_pa, "must be a positive yield stress [Pa]");
  }
  if (!(p.b_pa >= 0)) {
    complain("b_pa", p.b_pa, "must be >= 0 [Pa]");
  }
  if (!(p.n > 0 && p.n <= 1)) {
    complain("n", p.n, "should lie in (0, 1] for metals");
  }
  if (!(p.c >= 0)) {
    complain("c", p.c, "must be >= 0");
  }
  if (!(p.reference_strain_rate_1_s > 0)) {
    complain("reference_strain_rate_1_s", p.reference_strain_rate_1_s, "must be positive [1/s]");
  }
  if (!(p.min_rate_ratio > 0) || !(Real(1) + p.c * std::log(p.min_rate_ratio) > 0)) {
    complain("min_rate_ratio", p.min_rate_ratio,
             "must be positive with 1 + C ln(min_rate_ratio) > 0 (else the flow stress vanishes)");
  }
  if (p.thermal_softening) {
    if (!(p.melt_temperature_k > p.room_temperature_k)) {
      complain("melt_temperature_k", p.melt_temperature_k, "must exceed the room temperature [K]");
    }
    if (!(p.m > 0)) {
      complain("m", p.m, "must be positive");
    }
    if (!(p.specific_heat_j_kg_k > 0)) {
      complain("specific_heat_j_kg_k", p.specific_heat_j_kg_k, "must be positive [J/(kg K)]");
    }
    if (!(p.taylor_quinney >= 0 && p.taylor_quinney <= 1)) {
      complain("taylor_quinney", p.taylor_quinney, "must lie in [0, 1]");
    }
  }
  return problems;
}

/// The law in the strength interface (strength.hpp), found by its parameter type.
inline const ElasticParams& elastic_of(const JohnsonCookParams& law) {
  return law.elastic;
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

inline std::vector<ConstantProblem> strength_check_of(const JohnsonCookParams& law) {
  return johnson_cook_check(law);
}

}  // namespace crater::materials
