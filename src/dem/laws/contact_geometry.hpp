// DEM contact geometry and kinematics shared by every contact law in src/dem/laws/:
// effective radius, mass and elastic moduli; overlap, normal and lever arms of a touching pair;
// the relative velocity at the contact point including rotation. Templated on the dimension D:
// 2D disks carry one spin \omega_3 (a scalar), 3D spheres an angular-velocity vector \omega.
//
// Conventions (every law here uses them):
//   n   = (x_1 - x_2) / |x_1 - x_2|          unit normal from body 2 to body 1 (LIGGGHTS `en`)
//   δ   = R_1 + R_2 - |x_1 - x_2|             overlap [m], > 0 when touching
//   a_i = R_i - δ/2                           lever arm from centre i to the contact point [m]
//   c   = x_1 - a_1 n = x_2 + a_2 n           contact point, mid-way through the overlap
//   v_rel = v_1 - v_2 + \omega_1 \times (-a_1 n) - \omega_2 \times (a_2 n)
//                                             velocity of body 1's material at c relative to
//                                             body 2's [m/s]
//   v_n = v_rel \cdot n  (< 0 approaching),   v_t = v_rel - v_n n
// A force F on body 1 at c (and -F on body 2) gives the torques
//   \tau_1 = (-a_1 n) \times F,   \tau_2 = (a_2 n) \times (-F).
//
// Why a_i = R_i - δ/2 rather than R_i: the paper's eqs. 8, 15, 16 and 24 use R + U^n/2 with
// U^n = -δ (eq. 5), and LIGGGHTS uses the same arm (`cri = radi - 0.5*deltan`). Since then
// a_1 + a_2 = |x_1 - x_2|, the torques above conserve angular momentum exactly; with a_i = R_i
// (LAMMPS gran/*) they miss it by δ n \times F. The difference in v_rel is O(δ/R) ~ 1e-3.
//
// A wall (rigid plane or FE segment) is body 2 with R_2 -> infinity: R* = R_1, m* = m_1, the
// contact point is the closest wall point p, so a_1 = |x_1 - p| = R_1 - δ, a_2 = 0.
//
// References
//   [J85]  K. L. Johnson, "Contact Mechanics", Cambridge University Press (1985), §4.2.
//   [M49]  R. D. Mindlin, "Compliance of elastic bodies in contact", J. Appl. Mech. 16 (1949)
//          259-268.
//   [DRDM04] A. Di Renzo, F. P. Di Maio, "Comparison of contact-force models for the simulation
//          of collisions in DEM-based granular flow codes", Chem. Eng. Sci. 59 (2004) 525-541.
//   [LIGGGHTS] C. Kloss et al., LIGGGHTS-PUBLIC 3.8, src/normal_model_hertz.h,
//          src/tangential_model_history.h, src/global_properties.h (Yeff, Geff).
#pragma once

#include <cmath>
#include <type_traits>

#include <Eigen/Geometry>  // Vec<3>::cross

#include "core/axial_vec.hpp"
#include "core/types.hpp"

namespace crater::dem {

/// Angular velocity, torque or moment: one component \omega_3 (about the out-of-plane axis) in
/// 2D, a 3-vector in 3D.
template <int D>
using AngularVec = std::conditional_t<D == 2, Real, Vec<3>>;

/// Zero of AngularVec<D> (Eigen's default constructor leaves a Vec<3> uninitialised).
template <int D>
inline AngularVec<D> angular_zero() {
  return axial_zero<D>();
}

/// |\omega| of an AngularVec (the absolute value in 2D).
template <int D>
inline Real angular_norm(const AngularVec<D>& w) {
  if constexpr (D == 2) {
    return std::abs(w);
  } else {
    return w.norm();
  }
}

/// a . b of two AngularVecs (the product in 2D).
template <int D>
inline Real angular_dot(const AngularVec<D>& a, const AngularVec<D>& b) {
  if constexpr (D == 2) {
    return a * b;
  } else {
    return a.dot(b);
  }
}

// \omega \times r and r \times F (spin_cross, moment_of) are core/axial_vec.hpp's, shared with
// the contacts between parts (src/contact/).
using crater::moment_of;
using crater::spin_cross;

/// The component of v perpendicular to the unit vector n, rescaled to |v|: how an incremental
/// tangential quantity (shear displacement, bond shear force, rolling or bending moment) is
/// carried into the current contact plane when n has turned since the last step (LAMMPS
/// `pair granular`, after S. Luding, Granular Matter 10 (2008) 235, eq. 17). Plain projection
/// (LIGGGHTS tangential_model_history.h) would shrink the spring by 1 - cos(turn) every step.
/// Returns zero when v is parallel to n (then there is no direction to keep).
template <class V>
[[gnu::always_inline]] inline V rotate_into_tangent_plane(const V& v, const V& n) {
  // v - (v.n) n, component by component (the same arithmetic as the Eigen expression, which a
  // large pair loop may leave as an out-of-line call).
  const Real along = v.dot(n);
  V projected;
  for (Eigen::Index k = 0; k < v.size(); ++k) {
    projected[k] = v[k] - along * n[k];
  }
  const Real projected_sq = projected.squaredNorm();
  if (!(projected_sq > Real(0))) {
    return V::Zero();
  }
  return std::sqrt(v.squaredNorm() / projected_sq) * projected;
}

/// Whether \sqrt{norm_sq} > limit for limit >= 0, exactly as `std::sqrt(norm_sq) > limit`
/// decides it, with the root taken only when norm_sq is within 1e-14 of limit^2 (there the
/// rounding of the squares could decide otherwise). A friction law tests |F| against its
/// Coulomb bound this way and needs the root only when it has to scale F back.
inline bool root_exceeds(Real norm_sq, Real limit) {
  if (limit == Real(0)) {
    return norm_sq > Real(0);
  }
  const Real limit_sq = limit * limit;
  if (limit_sq > Real(1e-280)) {  // else limit^2 has lost digits to underflow
    if (norm_sq > limit_sq * Real(1 + 1e-14)) {
      return true;
    }
    if (norm_sq < limit_sq * Real(1 - 1e-14)) {
      return false;
    }
  }
  return std::sqrt(norm_sq) > limit;
}

// ---------------------------------------------------------------------------------------------
// Effective quantities of a pair.

/// Effective radius R* = R_1 R_2 / (R_1 + R_2) [m] ([J85] §4.2). A wall: R* = R_1.
inline Real effective_radius(Real r1, Real r2) {
  return r1 * r2 / (r1 + r2);
}

/// Effective (reduced) mass m* = m_1 m_2 / (m_1 + m_2) [kg] (per metre of depth in 2D when the
/// masses are). A wall: m* = m_1.
inline Real effective_mass(Real m1, Real m2) {
  return m1 * m2 / (m1 + m2);
}

/// Isotropic elastic constants of a grain or wall material. A rigid wall: E = +infinity.
struct ElasticMaterial {
  Real youngs_modulus_pa = 0;  // E [Pa]
  Real poisson_ratio = 0;      // \nu [-]
};

/// E = 2 G (1 + \nu) [Pa], for materials given by their shear modulus (the paper's sand:
/// G = 29 GPa, \nu = 0.2 -> E = 69.6 GPa).
inline Real youngs_modulus_from_shear(Real shear_modulus_pa, Real poisson_ratio) {
  return Real(2) * shear_modulus_pa * (Real(1) + poisson_ratio);
}

/// Effective Young's modulus of Hertz contact ([J85] §4.2):
///   1/E* = (1 - \nu_1^2)/E_1 + (1 - \nu_2^2)/E_2   [Pa].
/// A rigid body (E = inf) contributes 0.
inline Real effective_youngs_modulus(const ElasticMaterial& a, const ElasticMaterial& b) {
  return Real(1) / ((Real(1) - a.poisson_ratio * a.poisson_ratio) / a.youngs_modulus_pa +
                    (Real(1) - b.poisson_ratio * b.poisson_ratio) / b.youngs_modulus_pa);
}

/// Effective shear modulus of Mindlin no-slip contact ([M49]; [DRDM04]; LIGGGHTS `Geff`):
///   1/G* = (2 - \nu_1)/G_1 + (2 - \nu_2)/G_2
///        = 2(2 - \nu_1)(1 + \nu_1)/E_1 + 2(2 - \nu_2)(1 + \nu_2)/E_2
/// [Pa], with G = E / (2(1 + \nu)). The tangential stiffness is then k_t = 8 G* \sqrt{R* δ}.
inline Real effective_shear_modulus(const ElasticMaterial& a, const ElasticMaterial& b) {
  auto compliance = [](const ElasticMaterial& m) {
    return Real(2) * (Real(2) - m.poisson_ratio) * (Real(1) + m.poisson_ratio) /
           m.youngs_modulus_pa;
  };
  return Real(1) / (compliance(a) + compliance(b));
}

// ---------------------------------------------------------------------------------------------
// Geometry and kinematics of one pair at one instant.

/// Where two bodies touch (see the conventions at the top of this file).
template <int D>
struct ContactGeometry {
  Vec<D> normal = Vec<D>::Zero();  // n, unit, from body 2 to body 1
  Real overlap = 0;                // δ [m]; > 0 touching, < 0 a gap (bonds may span one)
  Real radius_eff = 0;             // R* [m]
  Real arm1 = 0;                   // a_1, centre of 1 to contact point [m]
  Real arm2 = 0;                   // a_2, centre of 2 to contact point [m] (0 for a wall)

  bool touching() const { return overlap > Real(0); }
};

namespace detail {

/// n = d / |d|; coincident centres (|d| = 0, never physical) get the first axis so the result
/// stays finite and deterministic.
template <int D>
inline Vec<D> unit_or_first_axis(const Vec<D>& d, Real length) {
  if (!(length > Real(0))) {
    return Vec<D>::Unit(0);
  }
  return (Real(1) / length) * d;  // one division, not D
}

}  // namespace detail

/// Two spheres (3D) or disks (2D) of radii r1, r2 at x1, x2 [m].
template <int D>
inline ContactGeometry<D> sphere_sphere_geometry(const Vec<D>& x1, Real r1, const Vec<D>& x2,
                                                 Real r2) {
  const Vec<D> d = x1 - x2;
  const Real distance = d.norm();
  ContactGeometry<D> g;
  g.normal = detail::unit_or_first_axis<D>(d, distance);
  g.overlap = r1 + r2 - distance;
  g.radius_eff = effective_radius(r1, r2);
  g.arm1 = r1 - Real(0.5) * g.overlap;
  g.arm2 = r2 - Real(0.5) * g.overlap;
  return g;
}

/// A sphere/disk of radius r1 at x1 against a wall whose point closest to x1 is wall_point [m]
/// (a plane, or the closest point of an FE surface segment, found by the caller).
template <int D>
inline ContactGeometry<D> sphere_wall_geometry(const Vec<D>& x1, Real r1,
                                               const Vec<D>& wall_point) {
  const Vec<D> d = x1 - wall_point;
  const Real distance = d.norm();
  ContactGeometry<D> g;
  g.normal = detail::unit_or_first_axis<D>(d, distance);
  g.overlap = r1 - distance;
  g.radius_eff = r1;
  g.arm1 = distance;
  g.arm2 = Real(0);
  return g;
}

/// Rigid-body motion of one body: centre velocity [m/s] and angular velocity [rad/s].
/// A wall: its velocity at the contact point and zero spin.
template <int D>
struct BodyMotion {
  Vec<D> velocity = Vec<D>::Zero();
  AngularVec<D> angular_velocity = angular_zero<D>();
};

/// Relative motion at the contact point.
template <int D>
struct RelativeVelocity {
  Vec<D> at_contact = Vec<D>::Zero();      // v_rel [m/s]
  Real normal = 0;                         // v_n = v_rel . n [m/s], < 0 approaching
  Vec<D> tangential = Vec<D>::Zero();      // v_t = v_rel - v_n n [m/s]
  AngularVec<D> spin = angular_zero<D>();  // \omega_1 - \omega_2 [rad/s] (rolling, bonds)
};

/// v_rel = v_1 - v_2 + \omega_1 \times (-a_1 n) - \omega_2 \times (a_2 n) and its parts.
template <int D>
[[gnu::always_inline]] inline RelativeVelocity<D> relative_velocity(const ContactGeometry<D>& g,
                                                                    const BodyMotion<D>& b1,
                                                                    const BodyMotion<D>& b2) {
  RelativeVelocity<D> r;
  // \omega_1 \times (a_1 n) + \omega_2 \times (a_2 n) = (a_1 \omega_1 + a_2 \omega_2) \times n: one
  // cross product.
  const AngularVec<D> spin_arm = g.arm1 * b1.angular_velocity + g.arm2 * b2.angular_velocity;
  r.at_contact = b1.velocity - b2.velocity - spin_cross<D>(spin_arm, g.normal);
  r.normal = r.at_contact.dot(g.normal);
  r.tangential = r.at_contact - r.normal * g.normal;
  r.spin = b1.angular_velocity - b2.angular_velocity;
  return r;
}

}  // namespace crater::dem
