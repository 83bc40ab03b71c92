// Absorbing (viscous) wall for grains: the Lysmer-Kuhlemeyer boundary [LK69] applied to the
// grains that touch a face of the domain, as the viscous boundaries of DEM codes apply it to
// boundary particles (force = traction x the particle's tributary area):
//
//   f_n = max(F_0 - \eta_n (v . n), 0)      along n (from the wall into the bed)     [N]
//   F_t = -\eta_t (v - (v . n) n)    on a grain of the bed (in_bed), else 0             [N]
//   \eta_n = \rho c_p A,   \eta_t = \rho c_s A                                        [N s/m]
//   A = 2r (2D, per metre of depth),  A = (2r)^2 (3D)                                 [m^2]
//
// v is the grain's centre velocity (the wall acts through the centre: no torque), \rho the
// bulk density of the bed behind the wall, c_p and c_s its wave speeds. A is the face area a
// grain of a square (cubic) lattice of pitch 2r stands for; then \eta_n = \rho c_p A is exactly
// the impedance of the lattice's columns, e.g. sqrt(k m) for a chain of grains m on springs k
// (\rho = m / (2r)^D, c_p = 2r sqrt(k/m)).
//
// F_0 is the static reaction: the wall's elastic normal force at the grain's overlap at t = 0
// (the bed's geostatic load on the face). It is held constant instead of following the overlap:
// a wall spring in parallel with the dashpot (Kelvin-Voigt) is a rigid wall for any pulse
// longer than a grain's contact time, since its force k_w u outgrows \eta_n v below the
// frequency k_w / \eta_n ~ sqrt(k/m); a linear chain with such a wall (k_w = k) reflects 93-98 %
// of the amplitude of pulses 10-40 grains long, with a held F_0 2-5 % (docs/validation.md). The
// price: the wall has no stiffness, so a grain that was not touching it at t = 0 is held only
// by the dashpot and creeps into it at F / \eta_n (for a 5 mm sand grain under its own weight,
// about 0.2 mm/s).
//
// The tangential dashpot acts on the grains of the bed inside, those another grain pushes on
// (the part passes in_bed): the S wave it absorbs travels in the bed. A grain the blast cut
// loose from the bed and that comes to rest on the face is not held up by it (with the
// dashpot, such grains hung on the side faces of the paper-20cm demo: the normal dashpot or
// the held reaction kept them pressed to the face, the tangential one carried their weight,
// and the surface probe took them for ground).
//
// The face is the ground beyond the model, so it stops where the ground did at t = 0: above
// the highest grain centre that touched it then, it is open air and applies nothing (the part
// keeps that height per face). Ejecta flying out over the rim leave through it.
//
// The face transmits: the part applies this force while the grain's centre is inside the face
// and less than r from it, and removes a grain whose centre crosses the face (its energy booked
// as outflow), instead of putting it back against the bed (docs/theory.md §3).
//
// Energy: F_0 (v . n) is work done on the bed from outside (like gravity); the rest,
// -(f_n - F_0)(v . n) + \eta_t |v_t|^2 >= 0, is dissipated by the dashpots.
//
// References
//   [LK69] J. Lysmer, R. L. Kuhlemeyer, "Finite dynamic model for infinite media", J. Eng.
//          Mech. Div. ASCE 95 (1969) 859-877.
#pragma once

#include <algorithm>

#include "core/types.hpp"

namespace crater::dem {

/// The bed behind an absorbing wall: \rho c_p and \rho c_s [kg/(m^2 s)].
struct AbsorbingWallParams {
  Real normal_impedance = 0;      // \rho c_p
  Real tangential_impedance = 0;  // \rho c_s
};

/// What an absorbing wall does to one grain this step.
template <int D>
struct AbsorbingWallForce {
  Vec<D> force = Vec<D>::Zero();  // f_n n + F_t [N]
  Real static_power = 0;          // F_0 (v . n) [W]: work rate of the held reaction
  Real dissipated_power = 0;      // dashpots, >= 0 [W]
};

/// A grain's face area on the wall: 2r per metre of depth (2D), (2r)^2 (3D)   [m^2 or m].
template <int D>
inline Real absorbing_wall_area(Real radius) {
  if constexpr (D == 2) {
    return 2 * radius;
  } else {
    return 4 * radius * radius;
  }
}

/// The absorbing wall's force on a grain touching it (see the file comment). normal: unit
/// vector from the wall into the bed; velocity: the grain's centre velocity [m/s];
/// static_reaction: F_0 [N].
template <int D>
inline AbsorbingWallForce<D> absorbing_wall_force(const AbsorbingWallParams& p, Real area,
                                                  const Vec<D>& normal, const Vec<D>& velocity,
                                                  Real static_reaction, bool in_bed = true) {
  AbsorbingWallForce<D> out;
  const Real vn = velocity.dot(normal);
  const Vec<D> vt = velocity - vn * normal;
  const Real eta_n = p.normal_impedance * area;
  const Real eta_t = in_bed ? p.tangential_impedance * area : Real(0);
  const Real fn = std::max(static_reaction - eta_n * vn, Real(0));
  out.force = fn * normal - eta_t * vt;
  out.static_power = static_reaction * vn;
  out.dissipated_power = -(fn - static_reaction) * vn + eta_t * vt.squaredNorm();
  return out;
}

}  // namespace crater::dem
