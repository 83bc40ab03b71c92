// Parallel bond (Potyondy & Cundall [PC04]; paper §II-A-2, eqs. 17-24): a cement beam of radius
// R̄ between two grains that carries force and moment in parallel with their contact, until its
// tensile or shear strength is reached.
//
// Section of the cement (3D: a disk of radius R̄; 2D: a strip 2R̄ wide, t = 1 m deep, so that
// forces and moments are per metre of depth):
//   3D: A = \pi R̄^2,   I = \pi R̄^4 / 4,   J = \pi R̄^4 / 2         [m^2], [m^4], [m^4]
//   2D: A = 2 R̄ t,     I = (2/3) R̄^3 t                            [m^2/m], [m^4/m]
// Incremental update from the bond's stress-free creation (eqs. 18-20; [PC04] eqs. 7-8, 12):
//   F̄_n <- F̄_n + k̄_n A v_n \Delta t          normal force, > 0 in tension (eq. 19)   [N]
//   F̄_s <- R_n(F̄_s) - k̄_s A v_t \Delta t     shear force on body 1 (eq. 20)          [N]
//   M̄_b <- R_n(M̄_b) - k̄_n I \omega_b \Delta t  bending moment on body 1 (eq. 18)       [N m]
//   M̄_t <- M̄_t - k̄_s J \omega_t \Delta t       twisting moment about n, 3D only        [N m]
// with v_n, v_t from contact_geometry.hpp (v_n > 0 separating), \omega_1 - \omega_2 split into
// its twist part \omega_t = (\omega_1 - \omega_2) . n and bending part \omega_b (all of it in
// 2D), and R_n the rotation into the current contact plane keeping magnitude. k̄_n, k̄_s are
// stiffnesses per unit area [Pa/m].
// Strength (eqs. 21-22; [PC04] eq. 13): the bond breaks when
//   \sigma = F̄_n / A + |M̄_b| R̄ / I  >= \bar\sigma_c      or
//   \tau   = |F̄_s| / A + |M̄_t| R̄ / J  >= \bar\tau_c        (the torsion term in 3D only);
// a broken bond carries nothing and is removed by the caller; the pair keeps its ordinary
// contact law (paper: "only that of the linear spring model").
// Forces on the bodies (eqs. 17, 23, 24): body 1 gets F = -F̄_n n + F̄_s at the contact point and
// the moment M̄ = M̄_b + M̄_t n; body 2 gets -F and -M̄:
//   \tau_1 = M̄ + (-a_1 n) x F̄_s,   \tau_2 = -M̄ + (a_2 n) x (-F̄_s).
// Stored energy: F̄_n^2/(2 k̄_n A) + |F̄_s|^2/(2 k̄_s A) + |M̄_b|^2/(2 k̄_n I) + M̄_t^2/(2 k̄_s J).
//
// Bond radius (paper, after eq. 16): R̄ = \lambda (R_A + R_B)/2 or \lambda R_A R_B/(R_A + R_B);
// [PC04]: R̄ = \lambda min(R_A, R_B). All three are offered (BondRadiusRule).
//
// References
//   [PC04] D. O. Potyondy, P. A. Cundall, "A bonded-particle model for rock", Int. J. Rock Mech.
//          Min. Sci. 41 (2004) 1329-1364.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/types.hpp"
#include "dem/laws/contact_geometry.hpp"

namespace crater::dem {

/// How the bond radius follows from the grain radii.
enum class BondRadiusRule {
  MinRadius,        // R̄ = \lambda min(R_1, R_2)         [PC04]
  MeanRadius,       // R̄ = \lambda (R_1 + R_2) / 2        paper
  EffectiveRadius,  // R̄ = \lambda R_1 R_2 / (R_1 + R_2)  paper
};

/// R̄ [m] from the multiplier \lambda [-] and the radii [m].
inline Real parallel_bond_radius(BondRadiusRule rule, Real multiplier, Real r1, Real r2) {
  switch (rule) {
    case BondRadiusRule::MinRadius:
      return multiplier * std::min(r1, r2);
    case BondRadiusRule::MeanRadius:
      return multiplier * Real(0.5) * (r1 + r2);
    case BondRadiusRule::EffectiveRadius:
      return multiplier * effective_radius(r1, r2);
  }
  return Real(0);
}

/// The five bond parameters of the paper ([PC04]); the radius lives in the bond state.
struct ParallelBondParams {
  Real normal_stiffness_pa_m = 0;  // k̄_n [Pa/m]
  Real shear_stiffness_pa_m = 0;   // k̄_s [Pa/m]
  Real tensile_strength_pa = 0;    // \bar\sigma_c [Pa]
  Real shear_strength_pa = 0;      // \bar\tau_c [Pa]
};

/// Area and second moments of the cement section (see the file comment).
struct BondSection {
  Real area = 0;           // A [m^2] (2D: per metre of depth)
  Real inertia = 0;        // I [m^4] (2D: per metre of depth)
  Real polar_inertia = 0;  // J [m^4] (3D only; 0 in 2D)
};

template <int D>
inline BondSection bond_section(Real radius) {
  constexpr Real depth = 1.0;  // t [m]: 2D quantities are per metre of depth
  if constexpr (D == 2) {
    return BondSection{.area = Real(2) * radius * depth,
                       .inertia = Real(2) / Real(3) * radius * radius * radius * depth,
                       .polar_inertia = Real(0)};
  } else {
    const Real r2 = radius * radius;
    return BondSection{.area = std::numbers::pi * r2,
                       .inertia = std::numbers::pi * r2 * r2 / Real(4),
                       .polar_inertia = std::numbers::pi * r2 * r2 / Real(2)};
  }
}

/// What a bond carries; stored per bond. A new bond: parallel_bond_state<D>(radius), all zero.
template <int D>
struct ParallelBondState {
  Real radius = 0;                                   // R̄ [m]
  Real normal_force = 0;                             // F̄_n [N], > 0 tension
  Vec<D> shear_force = Vec<D>::Zero();               // F̄_s on body 1 [N]
  AngularVec<D> bending_moment = angular_zero<D>();  // M̄_b on body 1 [N m] (3D: normal to n)
  Real twisting_moment = 0;                          // M̄_t on body 1 about n [N m] (3D only)
};

/// A stress-free bond of radius R̄ [m].
template <int D>
inline ParallelBondState<D> parallel_bond_state(Real radius) {
  ParallelBondState<D> s;
  s.radius = radius;
  return s;
}

/// Result of one bond update.
template <int D>
struct ParallelBondResult {
  Vec<D> force_on_1 = Vec<D>::Zero();             // -F̄_n n + F̄_s [N]; body 2 gets the opposite
  AngularVec<D> torque_on_1 = angular_zero<D>();  // [N m], about centre 1
  AngularVec<D> torque_on_2 = angular_zero<D>();  // [N m], about centre 2
  ParallelBondState<D> state;                     // updated state (at failure when broken)
  Real tensile_stress = 0;                        // \sigma [Pa]
  Real shear_stress = 0;                          // \tau [Pa]
  Real elastic_energy = 0;  // stored [J]; when broken, the energy lost with the bond
  bool broken = false;      // \sigma >= \bar\sigma_c or \tau >= \bar\tau_c: forces are zero
};

/// The two stresses the strength criteria test.
struct BondStresses {
  Real tensile = 0;  // \sigma [Pa]
  Real shear = 0;    // \tau [Pa]
};

/// Bond stresses of a state (eqs. 21-22).
template <int D>
inline BondStresses parallel_bond_stresses(const ParallelBondState<D>& s) {
  const BondSection sec = bond_section<D>(s.radius);
  const Real sigma =
      s.normal_force / sec.area + angular_norm<D>(s.bending_moment) * s.radius / sec.inertia;
  Real tau = s.shear_force.norm() / sec.area;
  if constexpr (D == 3) {
    tau += std::abs(s.twisting_moment) * s.radius / sec.polar_inertia;
  }
  return BondStresses{.tensile = sigma, .shear = tau};
}

/// Energy a bond state stores [J] (see the file comment); what is lost when it breaks.
template <int D>
inline Real parallel_bond_energy(const ParallelBondParams& p, const ParallelBondState<D>& s) {
  const BondSection sec = bond_section<D>(s.radius);
  auto energy = [](Real load, Real stiffness) {
    return stiffness > Real(0) ? Real(0.5) * load * load / stiffness : Real(0);
  };
  Real e = energy(s.normal_force, p.normal_stiffness_pa_m * sec.area) +
           energy(s.shear_force.norm(), p.shear_stiffness_pa_m * sec.area) +
           energy(angular_norm<D>(s.bending_moment), p.normal_stiffness_pa_m * sec.inertia);
  if constexpr (D == 3) {
    e += energy(s.twisting_moment, p.shear_stiffness_pa_m * sec.polar_inertia);
  }
  return e;
}

/// Advance a bond by dt [s] with the pair's current geometry and relative velocity, check its
/// strength, and return the forces it exerts (see the file comment).
template <int D>
inline ParallelBondResult<D> parallel_bond(const ParallelBondParams& p, const ContactGeometry<D>& g,
                                           const RelativeVelocity<D>& v,
                                           const ParallelBondState<D>& previous, Real dt) {
  const BondSection sec = bond_section<D>(previous.radius);
  const Vec<D>& n = g.normal;
  const Real kn_a = p.normal_stiffness_pa_m * sec.area;
  const Real ks_a = p.shear_stiffness_pa_m * sec.area;
  const Real kn_i = p.normal_stiffness_pa_m * sec.inertia;

  ParallelBondResult<D> out;
  ParallelBondState<D>& s = out.state;
  s.radius = previous.radius;
  s.normal_force = previous.normal_force + kn_a * v.normal * dt;
  s.shear_force = rotate_into_tangent_plane(previous.shear_force, n) - ks_a * dt * v.tangential;
  if constexpr (D == 2) {
    s.bending_moment = previous.bending_moment - kn_i * v.spin * dt;
  } else {
    const Real twist_rate = v.spin.dot(n);
    const Vec<3> bend_rate = v.spin - twist_rate * n;
    s.bending_moment =
        rotate_into_tangent_plane(previous.bending_moment, n) - kn_i * dt * bend_rate;
    s.twisting_moment =
        previous.twisting_moment - p.shear_stiffness_pa_m * sec.polar_inertia * twist_rate * dt;
  }

  const BondStresses stresses = parallel_bond_stresses<D>(s);
  out.tensile_stress = stresses.tensile;
  out.shear_stress = stresses.shear;

  out.elastic_energy = parallel_bond_energy<D>(p, s);

  out.broken = stresses.tensile >= p.tensile_strength_pa || stresses.shear >= p.shear_strength_pa;
  if (out.broken) {
    return out;  // forces and torques stay zero
  }
  out.force_on_1 = -s.normal_force * n + s.shear_force;
  AngularVec<D> bond_moment = s.bending_moment;
  if constexpr (D == 3) {
    bond_moment += s.twisting_moment * n;
  }
  out.torque_on_1 = bond_moment + moment_of<D>(-g.arm1 * n, s.shear_force);
  out.torque_on_2 = -bond_moment + moment_of<D>(g.arm2 * n, Vec<D>(-s.shear_force));
  return out;
}

}  // namespace crater::dem
