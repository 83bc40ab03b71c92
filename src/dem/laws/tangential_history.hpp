// Tangential sub-model shared by the linear and Hertz-Mindlin laws: an incremental ("history")
// shear spring with a dashpot and a Coulomb friction limit.
//
//   \xi      <- R_n(\xi) + v_t \Delta t                        (paper eqs. 7, 10, 12; [CS79])
//   F_t       = -k_t \xi - \gamma_t v_t                        [N], on body 1
//   |F_t|    <= \mu max(F_n, 0)                               (paper eq. 13: \mu |F_n|)
// \xi [m] is the shear displacement stored per contact across steps (the contact history);
// R_n carries it into the current tangent plane, keeping its length (rotate_into_tangent_plane).
//
// Coulomb limit and sliding, as LIGGGHTS `tangential history` does it: when the spring force
// |k_t \xi| exceeds the limit L = \mu max(F_n, 0) the contact slides, the spring is cut back to
// \xi = \xi L / (k_t |\xi|) (so it carries exactly the sliding force) and the dashpot is off.
// Two differences from LIGGGHTS 3.8, both deliberate (tests/verification/dem_oblique,
// tests/verification/dem_liggghts): (1) LIGGGHTS tests only the spring part, so while sticking
// |F_t| = |k_t\xi + \gamma_t v_t| can exceed the limit by up to \gamma_t|v_t|; here the total is
// capped as well (the dashpot part is reduced, the spring left as it is), so the Coulomb bound
// always holds; (2) LIGGGHTS takes \mu|F_n|, which keeps friction acting while a damped contact
// pulls at its end; here there is no friction without compression. In a 45-degree impact the
// two together change the tangential force by 8 % of its peak; head-on the codes agree to
// round-off.
//
// Energy bookkeeping (for a constant k_t it closes the balance of the time integration): the
// spring stores (1/2) k_t |\xi|^2; what the tangential force does beyond it is dissipated.
// Sticking, the dashpot's work, P_diss = -(F_t + k_t \xi_{new}) . v_t. Sliding, velocity
// Verlet moves the bodies under the mean of the spring force at the step's start and end
// (-k_t \xi_{old} and -k_t \xi_{new}, \xi_{old} carried into the current plane) over the
// step's displacement v_t \Delta t = \xi_{trial} - \xi_{old}; less the change of the stored
// energy that leaves
//   P_diss = (1/2) k_t (\xi_{old} + \xi_{new}) . (\xi_{trial} - \xi_{new}) / \Delta t,
// the friction force times the slip \xi_{trial} - \xi_{new} (mu F_n |v_t| in steady sliding;
// zero at mu = 0). It can be negative in a step where the slip turns back (the spring at the
// step's start pushed along the new motion). Charging the whole cut-back energy
// (1/2) k_t (|\xi_{trial}|^2 - |\xi_{new}|^2) instead, as an earlier version did, adds
// (1/2) k_t |v_t \Delta t|^2 per step of sliding: an error of first order in \Delta t that in a
// 45,000-sphere bed took 11 % of the energy in 2,000 steps. Hertz-Mindlin's
// k_t varies with δ, so its incremental spring is not exactly conservative ([DRDM05]); the
// mismatch is O(Δδ/δ) per step and shows up in the part's energy balance, not here.
//
// References
//   [CS79]  P. A. Cundall, O. D. L. Strack, "A discrete numerical model for granular
//           assemblies", Géotechnique 29 (1979) 47-65.
//   [DRDM05] A. Di Renzo, F. P. Di Maio, "An improved integral non-linear model for the contact
//           of particles in distinct element simulations", Chem. Eng. Sci. 60 (2005) 1303-1312.
//   [LIGGGHTS] LIGGGHTS-PUBLIC 3.8, src/tangential_model_history.h.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/types.hpp"
#include "dem/laws/contact_geometry.hpp"

namespace crater::dem {

/// The spring, dashpot and friction of one contact at one instant.
struct TangentialSpring {
  Real stiffness = 0;  // k_t [N/m]
  Real damping = 0;    // \gamma_t [N s/m]
  Real friction = 0;   // \mu [-]
};

/// Result of the tangential sub-model.
template <int D>
struct TangentialForce {
  Vec<D> force = Vec<D>::Zero();    // F_t on body 1 [N] (body 2 gets -F_t)
  Vec<D> history = Vec<D>::Zero();  // updated \xi [m], to store for the next step
  Real elastic_energy = 0;          // (1/2) k_t |\xi|^2 [J]
  Real dissipated_power = 0;        // P_diss [W] (see the file comment)
  bool sliding = false;             // the spring was cut back to the Coulomb limit
  bool limited = false;  // the limit decided the force (sliding, or the dashpot's sum cut back):
                         // only then does the result depend on \mu
};

/// The history spring with Coulomb limit (see the file comment), from the previous step's
/// history already carried into the current tangent plane (`carried` = R_n(\xi), see
/// history_tangential_force).
///   normal_force        F_n [N] (> 0 repulsive), sets the limit \mu max(F_n, 0)
///   tangential_velocity v_t [m/s]
///   dt                  \Delta t [s]
template <int D>
[[gnu::always_inline]] inline TangentialForce<D> carried_tangential_force(
    const TangentialSpring& spring, Real normal_force, const Vec<D>& tangential_velocity,
    const Vec<D>& carried, Real dt) {
  TangentialForce<D> out;
  const Vec<D> trial = carried + tangential_velocity * dt;
  // Friction only while the grains press together: the dashpot can make F_n pull at the end
  // of a damped impact, and friction from that pull would add tangential impulse that no
  // contact transmits (+6 % spin in the oblique-impact test with |F_n|, as LIGGGHTS has it).
  const Real limit = spring.friction * std::max(normal_force, Real(0));
  const Vec<D> spring_force = -spring.stiffness * trial;
  const Real spring_sq = spring_force.squaredNorm();
  if (root_exceeds(spring_sq, limit)) {
    // Sliding: keep the direction, cut the spring back to the limit; no dashpot.
    const Real scale = limit / std::sqrt(spring_sq);
    out.history = scale * trial;
    out.force = scale * spring_force;
    out.sliding = true;
    out.limited = true;
    // The bodies feel the mean of the step's first and last spring force (velocity Verlet):
    // its work over the step's displacement, less what the spring now holds more. At dt = 0
    // (the forces of t = 0, e.g. a settled packing's springs under the run's laws) a spring
    // beyond the limit is cut back before the initial energies are taken: nothing to book.
    out.dissipated_power = dt > 0 ? Real(0.5) * spring.stiffness *
                                        (carried + out.history).dot(trial - out.history) / dt
                                  : Real(0);
  } else {
    out.history = trial;
    const Vec<D> total = spring_force - spring.damping * tangential_velocity;
    const Real total_sq = total.squaredNorm();
    out.limited = root_exceeds(total_sq, limit);
    out.force = out.limited ? Vec<D>((limit / std::sqrt(total_sq)) * total) : total;
    out.dissipated_power = -(out.force - spring_force).dot(tangential_velocity);
  }
  out.elastic_energy = Real(0.5) * spring.stiffness * out.history.squaredNorm();
  return out;
}

/// The history spring with Coulomb limit (see the file comment).
///   normal_force        F_n [N] (> 0 repulsive), sets the limit \mu max(F_n, 0)
///   normal              n of the current step
///   tangential_velocity v_t [m/s]
///   history             \xi of the previous step [m] (zero for a new contact)
///   dt                  \Delta t [s]
template <int D>
[[gnu::always_inline]] inline TangentialForce<D> history_tangential_force(
    const TangentialSpring& spring, Real normal_force, const Vec<D>& normal,
    const Vec<D>& tangential_velocity, const Vec<D>& history, Real dt) {
  return carried_tangential_force<D>(spring, normal_force, tangential_velocity,
                                     rotate_into_tangent_plane(history, normal), dt);
}

}  // namespace crater::dem
