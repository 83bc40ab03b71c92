// Rolling resistance: the elastic-plastic spring-dashpot model ("model C", EPSD) assessed by
// Ai, Chen, Rotter & Ooi [ACRO11]. Not in the paper; an option (off by default, \mu_r = 0) for
// round grains, which without it pile far flatter than sand does (DESIGN §3).
//
//   \omega_r   = \omega_1 - \omega_2, minus its twist part (\omega_r . n) n in 3D     [rad/s]
//   k_r        = 2.25 k_n \mu_r^2 R*^2                                               [N m/rad]
//   M^k       <- R_n(M^k) - k_r \omega_r \Delta t,   |M^k| <= M_m = \mu_r R* |F_n|    [N m]
//   M^d        = -C_r \omega_r while |M^k| < M_m, 0 at the limit (Ai's f = 0)         [N m]
//   C_r        = \eta_r 2 \sqrt{I_r k_r}                                               [N m s]
//   I_r        = [(I_1 + m_1 r_1^2)^{-1} + (I_2 + m_2 r_2^2)^{-1}]^{-1}               [kg m^2]
//   torque on body 1: M^k + M^d,  on body 2: -(M^k + M^d).
// \mu_r [-] is the rolling friction coefficient, \eta_r [-] the rolling damping ratio ([ACRO11]
// use 0.3; 0 here by default, as LIGGGHTS `rolling_friction epsd2`). k_r is [ACRO11]'s
// stiffness after Iwashita & Oda [IO98]; k_n is the normal tangent stiffness dF_n/dδ that the
// contact law reports (ContactForce::normal_stiffness: k_n for the linear law, S_n for Hertz).
// M^k is stored per contact (the rolling history) and, like the shear spring, carried into the
// current tangent plane each step keeping its magnitude (a scalar in 2D: nothing to rotate).
// |F_n| as for the sliding limit (tangential_history.hpp).
//
// References
//   [ACRO11] J. Ai, J.-F. Chen, J. M. Rotter, J. Y. Ooi, "Assessment of rolling resistance
//            models in discrete element simulations", Powder Technol. 206 (2011) 269-282.
//   [IO98]   K. Iwashita, M. Oda, "Rolling resistance at contacts in simulation of shear band
//            development by DEM", J. Eng. Mech. 124 (1998) 285-292.
#pragma once

#include <cmath>

#include "core/types.hpp"
#include "dem/laws/contact_geometry.hpp"

namespace crater::dem {

/// Rolling-resistance parameters of one material pair.
struct RollingResistanceParams {
  Real friction = 0;       // \mu_r [-]; 0 switches the model off
  Real damping_ratio = 0;  // \eta_r [-]
};

/// Inertia data of one body for I_r: moment of inertia about its centre [kg m^2], mass [kg],
/// radius [m].
struct RollingBody {
  Real moment_of_inertia = 0;
  Real mass = 0;
  Real radius = 0;
};

/// I_r = [(I_1 + m_1 r_1^2)^{-1} + (I_2 + m_2 r_2^2)^{-1}]^{-1}   [kg m^2] ([ACRO11]).
inline Real rolling_inertia_eff(const RollingBody& b1, const RollingBody& b2) {
  const Real j1 = b1.moment_of_inertia + b1.mass * b1.radius * b1.radius;
  const Real j2 = b2.moment_of_inertia + b2.mass * b2.radius * b2.radius;
  return j1 * j2 / (j1 + j2);
}

/// I_r against a wall: I_1 + m_1 r_1^2   [kg m^2].
inline Real rolling_inertia_eff_wall(const RollingBody& b1) {
  return b1.moment_of_inertia + b1.mass * b1.radius * b1.radius;
}

/// k_r = 2.25 k_n \mu_r^2 R*^2   [N m/rad]; k_n [N/m], R* [m].
inline Real rolling_stiffness(Real rolling_friction, Real normal_stiffness, Real radius_eff) {
  return Real(2.25) * normal_stiffness * rolling_friction * rolling_friction * radius_eff *
         radius_eff;
}

/// What the normal contact law says about the pair this step.
struct RollingLoad {
  Real normal_force = 0;      // F_n [N]
  Real normal_stiffness = 0;  // k_n = dF_n/dδ [N/m]
  Real inertia_eff = 0;       // I_r [kg m^2] (only used when \eta_r > 0)
};

/// Result of the rolling sub-model.
template <int D>
struct RollingTorque {
  AngularVec<D> torque_on_1 = angular_zero<D>();  // M^k + M^d [N m]; body 2 gets the opposite
  AngularVec<D> history = angular_zero<D>();      // updated M^k [N m], to store
  Real elastic_energy = 0;                        // |M^k|^2 / (2 k_r) [J]
  Real dissipated_power = 0;                      // damper + plastic slip [W]
  bool at_limit = false;                          // |M^k| = M_m (fully mobilised)
};

/// Rolling resistance torque (see the file comment). history: M^k of the previous step.
template <int D>
inline RollingTorque<D> rolling_resistance(const RollingResistanceParams& p,
                                           const ContactGeometry<D>& g,
                                           const RelativeVelocity<D>& v, const RollingLoad& load,
                                           const AngularVec<D>& history, Real dt) {
  RollingTorque<D> out;
  const Real k_r = rolling_stiffness(p.friction, load.normal_stiffness, g.radius_eff);
  if (!(k_r > Real(0))) {
    return out;  // the model is off (\mu_r = 0) or the pair carries no load
  }
  AngularVec<D> omega_r = v.spin;
  AngularVec<D> previous = history;
  if constexpr (D == 3) {
    omega_r -= omega_r.dot(g.normal) * g.normal;  // twisting is not rolling
    previous = rotate_into_tangent_plane(previous, g.normal);
  }
  const AngularVec<D> trial = previous - k_r * dt * omega_r;
  const Real limit = p.friction * g.radius_eff * std::abs(load.normal_force);
  const Real trial_norm = angular_norm<D>(trial);
  if (trial_norm > limit) {
    out.history = (limit / trial_norm) * trial;
    out.torque_on_1 = out.history;
    out.at_limit = true;
    // As the tangential spring (tangential_history.hpp): the mean of the step's first and last
    // spring moment over the step's rotation, less the change of the stored energy.
    out.dissipated_power =
        angular_dot<D>(previous + out.history, trial - out.history) / (Real(2) * k_r * dt);
  } else {
    const Real c_r = p.damping_ratio * Real(2) * std::sqrt(load.inertia_eff * k_r);
    out.history = trial;
    out.torque_on_1 = trial - c_r * omega_r;
    out.dissipated_power = c_r * angular_norm<D>(omega_r) * angular_norm<D>(omega_r);
  }
  const Real m = angular_norm<D>(out.history);
  out.elastic_energy = Real(0.5) * m * m / k_r;
  return out;
}

}  // namespace crater::dem
