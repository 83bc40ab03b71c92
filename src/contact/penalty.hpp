// The penalty law every pairing uses (coupling.hpp has the equations): the normal spring with
// its dashpot, the regularised Coulomb friction, the reduced mass, and the step limit of one
// spring. Pure functions, inline so that the pairings' loops keep them in place.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/types.hpp"

namespace crater::contact {

/// Normal and tangential penalty force on side 1 for overlap delta along n (from 2 to 1), the
/// relative velocity v of side 1's contact point, the effective mass m [N]; `normal` gets F_n.
///   F_n = max(0, k delta - 2 xi sqrt(k m) v_n),  F_t = -min(mu F_n, sqrt(k m)/2 |v_t|) v_t/|v_t|
template <int D>
inline Vec<D> penalty_force(Real k, Real delta, const Vec<D>& n, const Vec<D>& v, Real m, Real xi,
                            Real mu, Real& normal) {
  const Real root = std::sqrt(k * m);
  const Real vn = v.dot(n);
  normal = std::max(Real(0), k * delta - 2 * xi * root * vn);
  Vec<D> f = normal * n;
  if (mu > 0 && normal > 0) {
    const Vec<D> vt = v - vn * n;
    const Real speed = vt.norm();
    // The dashpot that regularises sticking: c_t = sqrt(k m*) / 2. The tangential motion of a
    // rolling grain has an effective mass of m / (1 + m r^2 / I), down to m* / 3.5 for a
    // sphere, so a critically damped c_t = 2 sqrt(k m*) would be unstable at the step limit.
    if (speed > 0) f -= (std::min(mu * normal, Real(0.5) * root * speed) / speed) * vt;
  }
  return f;
}

/// m* = a b / (a + b) [kg]; a side without mass (not positive) leaves the other's.
inline Real reduced_mass(Real a, Real b) {
  if (!(a > 0)) return b;
  if (!(b > 0)) return a;
  return a * b / (a + b);
}

/// Step limit of a penalty spring k [N/m] on mass m [kg]: omega dt <= 1/2, i.e. at least 12
/// steps per period. The central-difference stability limit of a damped spring,
/// (2/omega)(sqrt(1 + xi^2) - xi), is ~4x larger, but an impact resolved in two or three steps
/// books its energy badly: an SPH blob hitting a plate at 200 m/s gained 10 % energy at
/// omega dt = 1.6, 0.4 % at 0.8, 0.06 % at 0.36 (tests/verification/contact_conservation).
inline Real spring_step(Real k, Real m, Real xi) {
  if (!(k > 0) || !(m > 0)) return std::numeric_limits<Real>::infinity();
  const Real omega = std::sqrt(k / m);
  return std::min(Real(0.5) / omega, 2 / omega * (std::sqrt(1 + xi * xi) - xi));
}

}  // namespace crater::contact
