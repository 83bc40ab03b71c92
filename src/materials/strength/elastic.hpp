// Isotropic linear elasticity (hypoelastic rate form), the elastic part of every strength law.
//
//   \lambda = E \nu / ((1 + \nu)(1 - 2\nu)),   \mu = G = E / (2 (1 + \nu)),
//   K = E / (3 (1 - 2\nu)),                    M = \lambda + 2\mu  (P-wave modulus)   [Pa]
//   \Delta\sigma = \lambda\, tr(\Delta\varepsilon)\, I + 2\mu\, \Delta\varepsilon
//   c_d = \sqrt{(\lambda + 2\mu) / \rho}   dilatational (P) wave speed [m/s]
//
// Used in rate form with an objective stress rate (fem/kinematics.hpp): the strain increment
// is \Delta\varepsilon = d\,\Delta t with d the rate of deformation. The dilatational speed is
// the same in plane strain and in 3D (1D-strain wave).
//
// References
//   [TG70] S. P. Timoshenko, J. N. Goodier, "Theory of Elasticity", 3rd ed., McGraw-Hill (1970),
//          §3 (Lame constants), §127 (dilatational waves).
#pragma once

#include <cmath>
#include <sstream>
#include <vector>

#include "core/types.hpp"
#include "materials/eos/constant_problem.hpp"
#include "materials/strength/stress_tensor.hpp"
#include "materials/strength/stress_update.hpp"

namespace crater::materials {

/// Isotropic elastic constants: Young's modulus E [Pa] and Poisson's ratio \nu [-].
struct ElasticParams {
  Real youngs_modulus_pa = 0;
  Real poisson_ratio = 0;
};

/// Steel as in the design notes (E = 200 GPa, \nu = 0.3); its density is 7850 kg/m^3.
inline ElasticParams steel_elastic() {
  return ElasticParams{.youngs_modulus_pa = 200e9, .poisson_ratio = 0.3};
}

/// Shear modulus \mu = G = E / (2 (1 + \nu)) [Pa].
inline Real shear_modulus(const ElasticParams& p) {
  return p.youngs_modulus_pa / (Real(2) * (Real(1) + p.poisson_ratio));
}

/// First Lame constant \lambda = E \nu / ((1 + \nu)(1 - 2\nu)) [Pa].
inline Real lame_lambda(const ElasticParams& p) {
  const Real nu = p.poisson_ratio;
  return p.youngs_modulus_pa * nu / ((Real(1) + nu) * (Real(1) - Real(2) * nu));
}

/// Bulk modulus K = E / (3 (1 - 2\nu)) [Pa].
inline Real bulk_modulus(const ElasticParams& p) {
  return p.youngs_modulus_pa / (Real(3) * (Real(1) - Real(2) * p.poisson_ratio));
}

/// P-wave (constrained) modulus M = \lambda + 2\mu [Pa].
inline Real p_wave_modulus(const ElasticParams& p) {
  return lame_lambda(p) + Real(2) * shear_modulus(p);
}

/// Dilatational wave speed c_d = \sqrt{(\lambda + 2\mu)/\rho} [m/s]; density [kg/m^3].
inline Real dilatational_wave_speed(const ElasticParams& p, Real density) {
  return std::sqrt(p_wave_modulus(p) / density);
}

/// Elastic stress increment \lambda tr(\Delta\varepsilon) I + 2\mu \Delta\varepsilon [Pa].
inline Mat3 elastic_stress_increment(const ElasticParams& p, const Mat3& strain_increment) {
  return lame_lambda(p) * strain_increment.trace() * Mat3::Identity() +
         Real(2) * shear_modulus(p) * strain_increment;
}

/// Problems with the constants, in words; empty when usable (E > 0, -1 < \nu < 1/2).
inline std::vector<ConstantProblem> elastic_check(const ElasticParams& p) {
  std::vector<ConstantProblem> problems;
  if (!std::isfinite(p.youngs_modulus_pa) || p.youngs_modulus_pa <= 0) {
    std::ostringstream os;
    os << "elastic: youngs_modulus_pa = " << p.youngs_modulus_pa << " must be positive [Pa]";
    problems.push_back({"youngs_modulus_pa", os.str()});
  }
  if (!std::isfinite(p.poisson_ratio) || p.poisson_ratio <= -1 || p.poisson_ratio >= 0.5) {
    std::ostringstream os;
    os << "elastic: poisson_ratio = " << p.poisson_ratio
       << " must lie in (-1, 0.5) (0.5 is incompressible: K and lambda are infinite)";
    problems.push_back({"poisson_ratio", os.str()});
  }
  return problems;
}

/// The law in the strength interface (strength.hpp), found by its parameter type.
inline const ElasticParams& elastic_of(const ElasticParams& law) {
  return law;
}

inline StressUpdate update_stress_of(const ElasticParams& law, const Mat3& stress,
                                     const Mat3& strain_increment,
                                     const MaterialPointState& /*state*/, Real /*dt*/,
                                     Real /*density*/) {
  return StressUpdate{.stress = stress + elastic_stress_increment(law, strain_increment)};
}

inline std::vector<ConstantProblem> strength_check_of(const ElasticParams& law) {
  return elastic_check(law);
}

}  // namespace crater::materials
