// Cundall's local (non-viscous) damping (paper eq. 25; [C87]; [PC04] §2.2):
//   F^d_i = -\alpha |F_i| sign(v_i)     per component i                       [N]
//   M^d_i = -\alpha |M_i| sign(\omega_i)  likewise for the torque            [N m]
// F (M) is the particle's unbalanced force (torque) — the sum of contact, bond, body and
// external forces — and v (\omega) its velocity (angular velocity). The damping is added to F
// before the velocity update; it removes the fraction \alpha of the work the unbalanced force
// would do, independently of frequency and mass. sign(0) = 0 (paper: "zero = 0").
// Which velocity: PFC uses the mid-step velocity of its central-difference scheme; in crater's
// velocity Verlet the force stage sees v^{n+1/2}, the same mid-step velocity.
// Constants (paper eq. 25): \alpha = 0.7 quasi-static (settling, equilibrium), \alpha = 0.157 for
// dynamics. For a single-degree-of-freedom oscillator \alpha \approx \pi \zeta, so 0.157 is a
// critical damping fraction \zeta of 5 % ([PFC]).
// Unit: 2D forces and torques per metre of depth, as the part's.
//
// References
//   [C87]  P. A. Cundall, "Distinct element models of rock and soil structure", in Analytical and
//          Computational Methods in Engineering Rock Mechanics, Allen & Unwin (1987) 129-163.
//   [PC04] D. O. Potyondy, P. A. Cundall, Int. J. Rock Mech. Min. Sci. 41 (2004) 1329-1364.
//   [PFC]  Itasca, PFC manual, "Local damping" (the \alpha-\zeta relation).
#pragma once

#include <cmath>

#include "core/types.hpp"
#include "dem/laws/contact_geometry.hpp"

namespace crater::dem {

/// \alpha for dynamic runs (the paper's blast: 5 % of critical).
inline constexpr Real kLocalDampingDynamic = 0.157;
/// \alpha for quasi-static runs (settling to geostatic equilibrium).
inline constexpr Real kLocalDampingQuasiStatic = 0.7;

/// A damping force or torque and the power it removes.
template <class V>
struct LocalDamping {
  V load;                     // F^d [N] or M^d [N m], to add to the unbalanced load
  Real dissipated_power = 0;  // -F^d . v = \alpha \sum_i |F_i| |v_i| >= 0 [W]
};

namespace detail {

inline Real sign_or_zero(Real x) {
  return x > Real(0) ? Real(1) : (x < Real(0) ? Real(-1) : Real(0));
}

/// Per-component damping of an Eigen vector load.
template <class V>
inline LocalDamping<V> local_damping_components(Real alpha, const V& load, const V& rate) {
  LocalDamping<V> out{V::Zero(), Real(0)};
  for (int i = 0; i < load.size(); ++i) {
    out.load[i] = -alpha * std::abs(load[i]) * sign_or_zero(rate[i]);
    out.dissipated_power -= out.load[i] * rate[i];
  }
  return out;
}

}  // namespace detail

/// Damping force of one particle: unbalanced force F [N], velocity v [m/s].
template <int D>
inline LocalDamping<Vec<D>> local_damping_force(Real alpha, const Vec<D>& unbalanced_force,
                                                const Vec<D>& velocity) {
  return detail::local_damping_components(alpha, unbalanced_force, velocity);
}

/// Damping torque of one particle: unbalanced torque M [N m], angular velocity \omega [rad/s]
/// (2D: the single component \omega_3).
template <int D>
inline LocalDamping<AngularVec<D>> local_damping_torque(Real alpha,
                                                        const AngularVec<D>& unbalanced_torque,
                                                        const AngularVec<D>& angular_velocity) {
  if constexpr (D == 2) {
    const Real m = -alpha * std::abs(unbalanced_torque) * detail::sign_or_zero(angular_velocity);
    return LocalDamping<Real>{m, -m * angular_velocity};
  } else {
    return detail::local_damping_components(alpha, unbalanced_torque, angular_velocity);
  }
}

}  // namespace crater::dem
