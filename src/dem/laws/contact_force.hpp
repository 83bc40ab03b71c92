// What a normal + tangential contact law returns for one pair at one step, and how the normal
// and tangential sub-model results combine into forces and torques on both bodies.
//
// A law is a value type with a parameter struct and two static functions, so a DEM pair loop can
// take it as a template parameter and stay branch-free (STYLE habit 1):
//   struct SomeLaw {
//     using Params = SomeParams;
//     template <int D>   // the roots and divisions of a pair (ContactPrep)
//     static ContactPrep<D> prepare(const Params&, const ContactGeometry<D>&, Real mass_eff,
//                                   const Vec<D>& shear_history);
//     template <int D>   // the force from them
//     static ContactForce<D> finish(const Params&, const ContactGeometry<D>&,
//                                   const RelativeVelocity<D>&, const ContactPrep<D>&, Real dt);
//   };
// plus what a DEM part asks of it (law_binding.hpp); law_force() runs both halves in one call.
// (HertzMindlin in hertz_mindlin.hpp, LinearSpring in linear_spring.hpp.) The law is pure: the
// updated shear history comes back in the result; the caller stores it with the contact.
#pragma once

#include "core/types.hpp"
#include "dem/laws/contact_geometry.hpp"
#include "dem/laws/tangential_history.hpp"

namespace crater::dem {

/// Result of a normal sub-model (scalars along n).
struct NormalForce {
  Real force = 0;             // F_n [N], > 0 repulsive, elastic + dashpot
  Real elastic_force = 0;     // F_n^el [N], the spring part alone
  Real stiffness = 0;         // tangent stiffness dF_n^el/dδ [N/m]
  Real elastic_energy = 0;    // \int F_n^el dδ [J]
  Real dissipated_power = 0;  // v_n (F_n^el - F_n) >= 0 [W]: the dashpot's work rate
};

/// What `Law::prepare` computes of a pair: the normal spring, the dashpot coefficients and the
/// shear history carried into the current tangent plane, the part of a law whose roots and
/// divisions depend on the geometry and the stored history alone. A pair loop prepares a batch
/// of contacts first, so that their roots overlap in the processor, and then finishes each
/// (`Law::finish`).
template <int D>
struct ContactPrep {
  NormalForce spring;           // the spring alone (force = elastic_force), set by the law
  Real normal_damping = 0;      // \gamma_n [N s/m]
  Real tangential_damping = 0;  // \gamma_t [N s/m]
  Vec<D> carried_history = Vec<D>::Zero();  // R_n(\xi) [m] (tangential_history.hpp)
};

/// Forces, torques and energies of one contact.
template <int D>
struct ContactForce {
  Vec<D> force_on_1 = Vec<D>::Zero();             // F_n n + F_t [N]; body 2 gets -force_on_1
  AngularVec<D> torque_on_1 = angular_zero<D>();  // (-a_1 n) x F_t [N m], about centre 1
  AngularVec<D> torque_on_2 = angular_zero<D>();  // (a_2 n) x (-F_t) [N m], about centre 2
  Real normal_force = 0;                          // F_n [N], > 0 repulsive
  Vec<D> tangential_force = Vec<D>::Zero();       // F_t on body 1 [N]
  Vec<D> shear_history = Vec<D>::Zero();          // updated \xi [m], to store
  Real normal_stiffness = 0;                      // dF_n^el/dδ [N/m] (rolling resistance uses it)
  Real elastic_energy = 0;                        // normal + tangential spring energy [J]
  Real dissipated_power = 0;                      // dashpots + sliding, >= 0 [W]
  bool sliding = false;                           // at the Coulomb limit, spring cut back
  bool limited = false;  // the Coulomb limit decided F_t (TangentialForce::limited)
};

/// Combine the normal and tangential parts at the contact point of g.
template <int D>
[[gnu::always_inline]] inline ContactForce<D> combine_contact_force(const ContactGeometry<D>& g,
                                                                    const NormalForce& n,
                                                                    const TangentialForce<D>& t) {
  ContactForce<D> out;
  out.normal_force = n.force;
  out.tangential_force = t.force;
  out.force_on_1 = n.force * g.normal + t.force;
  // The normal part acts along the line of centres and has no moment about either centre.
  // (-a_1 n) \times F_t = -a_1 (n \times F_t) and (a_2 n) \times (-F_t) = -a_2 (n \times F_t).
  const AngularVec<D> turn = moment_of<D>(g.normal, t.force);
  out.torque_on_1 = -g.arm1 * turn;
  out.torque_on_2 = -g.arm2 * turn;
  out.shear_history = t.history;
  out.normal_stiffness = n.stiffness;
  out.elastic_energy = n.elastic_energy + t.elastic_energy;
  out.dissipated_power = n.dissipated_power + t.dissipated_power;
  out.sliding = t.sliding;
  out.limited = t.limited;
  return out;
}

/// Adds the normal dashpot to a spring-only NormalForce (force, elastic_force, stiffness and
/// elastic_energy set by the normal law): F_n = F_n^el - \gamma_n v_n [N], with \gamma_n [N s/m]
/// and v_n [m/s] (< 0 approaching, so the dashpot pushes apart while approaching). With
/// limit_attractive_force (LIGGGHTS `limitForce`) F_n is clamped to >= 0.
inline NormalForce add_normal_dashpot(NormalForce spring, Real dashpot, Real normal_velocity,
                                      bool limit_attractive_force) {
  NormalForce out = spring;
  out.force = spring.elastic_force - dashpot * normal_velocity;
  if (limit_attractive_force && out.force < Real(0)) {
    out.force = Real(0);
  }
  out.dissipated_power = normal_velocity * (spring.elastic_force - out.force);
  return out;
}

/// The half of a law that `Law::finish` runs from its prepared part, the same for every law
/// here: the normal dashpot on the prepared spring, the history spring of stiffness
/// shear_stiffness [N/m] with friction \mu from the carried history, and the forces and torques
/// on both bodies. v: velocities at the contact, dt [s].
template <int D>
[[gnu::always_inline]] inline ContactForce<D> finish_spring_dashpot(
    const ContactGeometry<D>& g, const RelativeVelocity<D>& v, const ContactPrep<D>& part,
    Real shear_stiffness, Real friction, bool limit_attractive_force, Real dt) {
  const NormalForce normal =
      add_normal_dashpot(part.spring, part.normal_damping, v.normal, limit_attractive_force);
  const TangentialForce<D> tangential = carried_tangential_force<D>(
      TangentialSpring{
          .stiffness = shear_stiffness, .damping = part.tangential_damping, .friction = friction},
      normal.force, v.tangential, part.carried_history, dt);
  return combine_contact_force<D>(g, normal, tangential);
}

/// A law's force on a touching pair in one call: Law::finish of Law::prepare. mass_eff m* [kg],
/// shear_history \xi of the previous step [m] (zero for a new contact), dt [s].
template <class Law, int D>
[[gnu::always_inline]] inline ContactForce<D> law_force(const typename Law::Params& p,
                                                        const ContactGeometry<D>& g,
                                                        const RelativeVelocity<D>& v, Real mass_eff,
                                                        const Vec<D>& shear_history, Real dt) {
  return Law::template finish<D>(p, g, v, Law::template prepare<D>(p, g, mass_eff, shear_history),
                                 dt);
}

}  // namespace crater::dem
