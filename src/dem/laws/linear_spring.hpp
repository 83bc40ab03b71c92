// Linear spring-dashpot contact with an incremental shear spring and Coulomb friction
// (paper §II-A-1, eqs. 2-16; Cundall & Strack [CS79]).
//
//   F_n = k_n δ - c_n v_n,                 c_n = 2 \zeta \sqrt{k_n m*}         (eqs. 5, 9, 11)
//   \xi <- R_n(\xi) + v_t \Delta t,  F_t = -k_s \xi - c_s v_t,  c_s = 2 \zeta \sqrt{k_s m*}
//                                                                          (eqs. 7, 8, 10, 12)
//   |F_t| <= \mu |F_n|                                                     (eq. 13)
//   force on body 1: F_n n + F_t,   torques (-a_1 n) x F_t and (a_2 n) x (-F_t)  (eqs. 14-16)
// with \zeta = -\ln e / \sqrt{\pi^2 + \ln^2 e} (viscous_damping.hpp), so a head-on collision
// that ends at δ = 0 has restitution e exactly:
//   e = \exp(-\pi \zeta / \sqrt{1 - \zeta^2}),   t_c = \pi / \sqrt{(k_n/m*)(1 - \zeta^2)}.
// Units: k_n, k_s [N/m], F [N] (per metre of depth in 2D, where k is per metre too).
//
// Differences from the paper's text, all without effect on the result:
// - The paper accumulates F_n incrementally (eq. 6, 9, 11) so that bonded particles placed with
//   an overlap start unloaded. For a contact that starts touching at δ = 0 the increments sum to
//   k_n δ exactly, and bonded pairs carry their stress-free start in the parallel bond
//   (parallel_bond.hpp), so the total overlap is used here.
// - Eq. 13 limits the scalar F^s; in 3D the limit applies to the vector |F_t| (same in 2D).
// - The paper's n (eq. 2) points from A to B; here n points from body 2 to body 1, F_n > 0 is
//   repulsive (contact_geometry.hpp).
//
// References
//   [CS79] P. A. Cundall, O. D. L. Strack, Géotechnique 29 (1979) 47-65.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "core/types.hpp"
#include "dem/laws/contact_force.hpp"
#include "dem/laws/contact_geometry.hpp"
#include "dem/laws/law_binding.hpp"
#include "dem/laws/tangential_history.hpp"
#include "dem/laws/viscous_damping.hpp"

namespace crater::dem {

/// Parameters of one material pair. Build with linear_spring_params().
struct LinearSpringParams {
  Real normal_stiffness_n_m = 0;        // k_n [N/m]
  Real shear_stiffness_n_m = 0;         // k_s [N/m]
  Real damping_ratio = 0;               // \zeta from the restitution e [-]
  Real friction = 0;                    // \mu [-]
  bool tangential_damping = true;       // c_s on
  bool limit_attractive_force = false;  // clamp F_n >= 0 (then the restitution exceeds e)
};

/// Parameters from k_n, k_s [N/m], restitution e in (0, 1] and friction \mu.
inline LinearSpringParams linear_spring_params(Real normal_stiffness, Real shear_stiffness,
                                               Real restitution, Real friction) {
  LinearSpringParams p;
  p.normal_stiffness_n_m = normal_stiffness;
  p.shear_stiffness_n_m = shear_stiffness;
  p.damping_ratio = damping_ratio_from_restitution(restitution);
  p.friction = friction;
  return p;
}

/// The law as a type, for a pair loop templated on it (contact_force.hpp), and what a DEM part
/// asks of it (law_binding.hpp).
struct LinearSpring {
  using Params = LinearSpringParams;

  /// The law's roots and divisions (contact_force.hpp, ContactPrep): the linear spring, both
  /// dashpot coefficients (mass_eff m* [kg]) and the shear history \xi [m] carried into the
  /// current tangent plane.
  template <int D>
  [[gnu::always_inline]] static ContactPrep<D> prepare(const Params& p, const ContactGeometry<D>& g,
                                                       Real mass_eff, const Vec<D>& shear_history) {
    ContactPrep<D> out;
    const Real delta = std::max(g.overlap, Real(0));
    out.spring.elastic_force = p.normal_stiffness_n_m * delta;
    out.spring.force = out.spring.elastic_force;
    out.spring.stiffness = p.normal_stiffness_n_m;
    out.spring.elastic_energy = Real(0.5) * out.spring.elastic_force * delta;
    out.normal_damping =
        linear_dashpot_coefficient(p.damping_ratio, p.normal_stiffness_n_m, mass_eff);
    out.tangential_damping =
        p.tangential_damping
            ? linear_dashpot_coefficient(p.damping_ratio, p.shear_stiffness_n_m, mass_eff)
            : Real(0);
    out.carried_history = rotate_into_tangent_plane(shear_history, g.normal);
    return out;
  }
  /// The force from the prepared part (see linear_spring).
  template <int D>
  [[gnu::always_inline]] static ContactForce<D> finish(const Params& p, const ContactGeometry<D>& g,
                                                       const RelativeVelocity<D>& v,
                                                       const ContactPrep<D>& part, Real dt) {
    return finish_spring_dashpot<D>(g, v, part, p.shear_stiffness_n_m, p.friction,
                                    p.limit_attractive_force, dt);
  }

  /// The part's springs k_n, k_s [N/m] with the grains' restitution and friction; walls take
  /// the same springs with their own friction and restitution.
  static LawPair<LinearSpring> part_laws(const Settings& dem, const GranularMaterial& grain);
  static bool row_of_spheres(const Settings& /*dem*/) { return false; }
  /// No step of its own: the stiffer spring, max(k_n, k_s), for the part's f sqrt(m / k).
  static LawStep part_step(const LawStepQuery& query) {
    LawStep s;
    s.stiffness_n_m = std::max(query.dem.normal_stiffness_n_m, query.dem.shear_stiffness_n_m);
    return s;
  }
  /// A chain (square/cubic lattice) of the mean grain: c_p = 2 r \sqrt{k_n / m} [m/s].
  static std::optional<Real> p_wave_speed(const Settings& dem, const MeanGrain& mean) {
    return 2 * mean.radius_m * std::sqrt(dem.normal_stiffness_n_m / mean.mass_kg);
  }
};

/// Linear spring-dashpot force on a touching pair (see the file comment). mass_eff m* [kg],
/// shear_history \xi of the previous step [m], dt [s].
template <int D>
inline ContactForce<D> linear_spring(const LinearSpringParams& p, const ContactGeometry<D>& g,
                                     const RelativeVelocity<D>& v, Real mass_eff,
                                     const Vec<D>& shear_history, Real dt) {
  return law_force<LinearSpring, D>(p, g, v, mass_eff, shear_history, dt);
}

inline LawPair<LinearSpring> LinearSpring::part_laws(const Settings& dem,
                                                     const GranularMaterial& grain) {
  return {linear_spring_params(dem.normal_stiffness_n_m, dem.shear_stiffness_n_m, grain.restitution,
                               grain.friction),
          linear_spring_params(dem.normal_stiffness_n_m, dem.shear_stiffness_n_m,
                               dem.wall_restitution, dem.wall_friction)};
}

/// Duration of a head-on linear spring-dashpot contact (ending at δ = 0):
///   t_c = \pi / \sqrt{(k_n / m*)(1 - \zeta^2)}   [s].
/// The usual stable step is a small fraction of it (or of 2\sqrt{m/k_n}).
inline Real linear_spring_contact_time(Real normal_stiffness, Real mass_eff, Real damping_ratio) {
  return std::numbers::pi /
         std::sqrt(normal_stiffness / mass_eff * (Real(1) - damping_ratio * damping_ratio));
}

}  // namespace crater::dem
