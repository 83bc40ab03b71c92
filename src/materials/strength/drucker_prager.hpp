// Drucker-Prager perfect plasticity with return mapping to the cone and to its apex, for soils
// (the continuum-soil comparison and the tunnel validation, paper §IV).
//
// Yield function [DP52] (tension positive, I_1 = tr \sigma, J_2 = s:s/2):
//   f(\sigma) = \sqrt{J_2} + \alpha I_1 - k <= 0                       [Pa]
// Plastic potential g = \sqrt{J_2} + \beta I_1 (\beta = \alpha: associative; \beta < \alpha:
// less dilatant). Perfect plasticity (\alpha, k constant).
//
// Return mapping from an elastic trial stress (s^{tr}, I_1^{tr}) ([SH98] §3.3; [dSN08] §8.3.2):
//   cone:  \Delta\gamma = f^{tr} / (\mu + 9 K \alpha \beta)
//          \sqrt{J_2} = \sqrt{J_2^{tr}} - \mu\Delta\gamma,   I_1 = I_1^{tr} - 9 K \beta
//          \Delta\gamma s = (\sqrt{J_2}/\sqrt{J_2^{tr}})\, s^{tr}
//   valid while \sqrt{J_2^{tr}} - \mu\Delta\gamma >= 0; otherwise the trial stress lies beyond
//   the apex and returns to it:
//   apex:  s = 0,  I_1 = k / \alpha  (\sigma = k/(3\alpha) I)
// Plastic strain increment \Delta\varepsilon^p = C^{-1} : (\sigma^{tr} - \sigma); plastic work
// \Delta W_p = \sigma : \Delta\varepsilon^p [J/m^3].
//
// Fits to Mohr-Coulomb (cohesion c, friction angle \phi) [C84, dSN08 §6.4.4]:
//   outer cone (triaxial compression meridian):
//       \alpha = 2 \sin\phi / (\sqrt3 (3 - \sin\phi)),  k = 6 c \cos\phi / (\sqrt3 (3 - \sin\phi))
//   inner cone (triaxial extension meridian): 3 + \sin\phi in place of 3 - \sin\phi
//   plane strain (same collapse load in plane strain, associative flow):
//       \alpha = \tan\phi / \sqrt{9 + 12 \tan^2\phi},  k = 3 c / \sqrt{9 + 12 \tan^2\phi}
//
// References
//   [DP52]  D. C. Drucker, W. Prager, "Soil mechanics and plastic analysis or limit design",
//           Q. Appl. Math. 10 (1952) 157-165.
//   [SH98]  J. C. Simo, T. J. R. Hughes, "Computational Inelasticity", Springer (1998).
//   [dSN08] E. A. de Souza Neto, D. Peric, D. R. J. Owen, "Computational Methods for
//           Plasticity", Wiley (2008), §6.4.4 and §8.3.
//   [C84]   W. F. Chen, "Plasticity in Reinforced Concrete" / W. F. Chen, E. Mizuno, "Nonlinear
//           Analysis in Soil Mechanics", Elsevier (1990), ch. 5.
#pragma once

#include <cmath>
#include <sstream>
#include <vector>

#include "core/types.hpp"
#include "materials/eos/constant_problem.hpp"
#include "materials/strength/elastic.hpp"
#include "materials/strength/stress_tensor.hpp"
#include "materials/strength/stress_update.hpp"

namespace crater::materials {

/// Drucker-Prager constants.
///   alpha   friction coefficient \alpha [-] (>= 0)
///   k_pa    cohesion-like intercept k [Pa] (>= 0)
///   beta    dilatancy coefficient \beta of the plastic potential [-] (= alpha: associative)
struct DruckerPragerParams {
  ElasticParams elastic;
  Real alpha = 0;
  Real k_pa = 0;
  Real beta = 0;
};

/// Which Mohr-Coulomb meridian or condition a Drucker-Prager cone is fitted to.
enum class MohrCoulombFit { kCompressionCone, kExtensionCone, kPlaneStrain };

/// Drucker-Prager constants matching Mohr-Coulomb (cohesion [Pa], friction and dilation angles
/// [rad]) by `fit` (formulas in the header comment). The dilation angle gives \beta by the same
/// formula as \alpha.
inline DruckerPragerParams drucker_prager_from_mohr_coulomb(const ElasticParams& elastic,
                                                            Real cohesion_pa, Real friction_rad,
                                                            Real dilation_rad, MohrCoulombFit fit) {
  const Real sqrt3 = std::sqrt(Real(3));
  auto slope = [&](Real angle) {
    switch (fit) {
      case MohrCoulombFit::kCompressionCone:
        return Real(2) * std::sin(angle) / (sqrt3 * (Real(3) - std::sin(angle)));
      case MohrCoulombFit::kExtensionCone:
        return Real(2) * std::sin(angle) / (sqrt3 * (Real(3) + std::sin(angle)));
      case MohrCoulombFit::kPlaneStrain:
      default: {
        const Real t = std::tan(angle);
        return t / std::sqrt(Real(9) + Real(12) * t * t);
      }
    }
  };
  Real k = 0;
  const Real s = std::sin(friction_rad);
  switch (fit) {
    case MohrCoulombFit::kCompressionCone:
      k = Real(6) * cohesion_pa * std::cos(friction_rad) / (sqrt3 * (Real(3) - s));
      break;
    case MohrCoulombFit::kExtensionCone:
      k = Real(6) * cohesion_pa * std::cos(friction_rad) / (sqrt3 * (Real(3) + s));
      break;
    case MohrCoulombFit::kPlaneStrain: {
      const Real t = std::tan(friction_rad);
      k = Real(3) * cohesion_pa / std::sqrt(Real(9) + Real(12) * t * t);
      break;
    }
  }
  return DruckerPragerParams{
      .elastic = elastic, .alpha = slope(friction_rad), .k_pa = k, .beta = slope(dilation_rad)};
}

/// Yield function f = \sqrt{J_2} + \alpha I_1 - k [Pa] (f <= 0 admissible).
inline Real drucker_prager_yield(const DruckerPragerParams& p, const Mat3& stress) {
  return std::sqrt(second_invariant(deviator(stress))) + p.alpha * stress.trace() - p.k_pa;
}

/// Outcome of one Drucker-Prager return.
struct DruckerPragerReturn {
  Mat3 stress;                                   // \sigma_{n+1} [Pa]
  Real plastic_multiplier = 0;                   // \Delta\gamma [-] (cone); 0 at the apex
  Real plastic_work_j_m3 = 0;                    // \sigma : \Delta\varepsilon^p [J/m^3]
  Real equivalent_plastic_strain_increment = 0;  // \sqrt{2/3 \Delta e^p : \Delta e^p} [-]
  bool yielded = false;
  bool apex = false;
};

/// Return of an elastic trial stress [Pa] to the Drucker-Prager surface.
inline DruckerPragerReturn drucker_prager_return(const DruckerPragerParams& p,
                                                 const Mat3& trial_stress) {
  DruckerPragerReturn out;
  out.stress = trial_stress;
  const Real f_trial = drucker_prager_yield(p, trial_stress);
  if (f_trial <= 0) {
    return out;
  }
  out.yielded = true;
  const Real mu = shear_modulus(p.elastic);
  const Real bulk = bulk_modulus(p.elastic);
  const Mat3 s_trial = deviator(trial_stress);
  const Real i1_trial = trial_stress.trace();
  const Real sqrt_j2_trial = std::sqrt(second_invariant(s_trial));
  const Real gamma = f_trial / (mu + Real(9) * bulk * p.alpha * p.beta);
  Mat3 s_new;
  Real i1_new = 0;
  if (sqrt_j2_trial - mu * gamma >= 0 || p.alpha <= 0) {
    const Real sqrt_j2 = sqrt_j2_trial - mu * gamma;
    s_new = (sqrt_j2_trial > 0 ? sqrt_j2 / sqrt_j2_trial : Real(0)) * s_trial;
    i1_new = i1_trial - Real(9) * bulk * p.beta * gamma;
    out.plastic_multiplier = gamma;
  } else {
    s_new.setZero();
    i1_new = p.k_pa / p.alpha;
    out.apex = true;
  }
  out.stress = s_new + (i1_new / Real(3)) * Mat3::Identity();
  const Mat3 ds = s_trial - s_new;  // = 2 mu \Delta e^p
  out.plastic_work_j_m3 = s_new.cwiseProduct(ds).sum() / (Real(2) * mu) +
                          (i1_new / Real(3)) * (i1_trial - i1_new) / (Real(3) * bulk);
  out.equivalent_plastic_strain_increment =
      std::sqrt(Real(2) / Real(3) * ds.cwiseProduct(ds).sum()) / (Real(2) * mu);
  return out;
}

/// Problems with the constants, in words; empty when usable.
inline std::vector<ConstantProblem> drucker_prager_check(const DruckerPragerParams& p) {
  std::vector<ConstantProblem> problems = elastic_check(p.elastic);
  auto complain = [&problems](const char* key, Real value, const char* expected) {
    std::ostringstream os;
    os << "Drucker-Prager: " << key << " = " << value << " " << expected;
    problems.push_back({key, os.str()});
  };
  if (!(p.alpha >= 0)) {
    complain("alpha", p.alpha, "must be >= 0");
  }
  if (!(p.k_pa >= 0)) {
    complain("k_pa", p.k_pa, "must be >= 0 [Pa]");
  }
  if (!(p.beta >= 0 && p.beta <= p.alpha + 1e-15)) {
    complain("beta", p.beta, "must lie in [0, alpha] (dilatancy at most associative)");
  }
  if (p.alpha <= 0 && p.k_pa <= 0) {
    complain("k_pa", p.k_pa, "must be positive when alpha = 0 (von Mises with no strength)");
  }
  return problems;
}

/// The law in the strength interface (strength.hpp), found by its parameter type.
inline const ElasticParams& elastic_of(const DruckerPragerParams& law) {
  return law.elastic;
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

inline std::vector<ConstantProblem> strength_check_of(const DruckerPragerParams& law) {
  return drucker_prager_check(law);
}

}  // namespace crater::materials
