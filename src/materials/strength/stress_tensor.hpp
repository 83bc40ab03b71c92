// Small helpers on the 3x3 Cauchy stress and strain tensors shared by the strength laws.
//
// Every strength law works on full 3x3 tensors whatever the dimension of the part: a plane
// strain element (D = 2) still carries \sigma_{zz} (and \varepsilon_{zz} = 0), so the laws are
// written once. Sign convention: tension positive; the pressure is p = -tr(\sigma)/3 (positive
// in compression).
#pragma once

#include <cmath>

#include "core/types.hpp"

namespace crater::materials {

/// A 3x3 stress [Pa], strain [-] or strain-rate [1/s] tensor (symmetric unless stated).
using Mat3 = Eigen::Matrix<Real, 3, 3>;

/// First invariant I_1 = tr(\sigma).
inline Real first_invariant(const Mat3& t) {
  return t.trace();
}

/// Pressure p = -tr(\sigma)/3 [Pa], positive in compression.
inline Real pressure_of(const Mat3& stress) {
  return -stress.trace() / Real(3);
}

/// Deviator s = \sigma - (tr \sigma / 3) I.
inline Mat3 deviator(const Mat3& t) {
  return t - (t.trace() / Real(3)) * Mat3::Identity();
}

/// Second invariant of a deviator, J_2 = s:s / 2.
inline Real second_invariant(const Mat3& s) {
  return Real(0.5) * s.cwiseProduct(s).sum();
}

/// Von Mises equivalent stress \sigma_{vm} = \sqrt{3 J_2} = \sqrt{(3/2) s:s} [Pa].
inline Real von_mises(const Mat3& stress) {
  return std::sqrt(Real(3) * second_invariant(deviator(stress)));
}

}  // namespace crater::materials
