// Boundary pieces of an FEM part that need no more than its nodes (fem_part.cpp holds the rest):
// Lysmer-Kuhlemeyer dashpots on boundary faces, and planar rigid walls.
//
// A rigid wall (LS-DYNA's *RIGIDWALL_PLANAR) is a fixed plane through a point with a unit normal
// pointing to the side the part is on. It holds nodes kinematically, as LS-DYNA's does: a node
// that would cross the plane in the coming step has the inward part of its normal velocity
// removed (it lands on the plane, not beyond), and Coulomb friction takes up to friction x that
// change from its tangential velocity, never reversing it. A node pulled away by its element
// leaves the plane freely, so a body can rebound. The kinetic energy the wall removes is its
// (negative) work, booked with the part's external work, so the energy balance closes.
#pragma once

#include <fmt/format.h>
#include <cmath>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "fem/explicit_mesh.hpp"
#include "fem/settings.hpp"
#include "materials/strength/strength.hpp"

namespace crater::fem {

template <int D>
using MatD = Eigen::Matrix<Real, D, D>;

template <int D>
struct RigidWall {
  Vec<D> point = Vec<D>::Zero();
  Vec<D> normal = Vec<D>::Zero();  // unit, towards the part
  Real friction = 0;
};

/// The walls of [[parts.fem.rigid_walls]] for a part whose nodes are at `x`; a node that starts
/// behind one is refused (InputError: the normal points to the part's side).
template <int D>
std::vector<RigidWall<D>> rigid_walls(const std::vector<RigidWallSettings>& settings,
                                      const std::vector<Vec<D>>& x, const std::string& part) {
  std::vector<RigidWall<D>> walls;
  for (std::size_t k = 0; k < settings.size(); ++k) {
    RigidWall<D> w;
    for (int d = 0; d < D; ++d) {
      w.point[d] = settings[k].point_m[static_cast<std::size_t>(d)];
      w.normal[d] = settings[k].normal[static_cast<std::size_t>(d)];
    }
    w.normal.normalize();
    w.friction = settings[k].friction;
    for (std::size_t n = 0; n < x.size(); ++n)
      if ((x[n] - w.point).dot(w.normal) < -1e-9 * (1 + w.point.norm()))
        throw InputError(settings[k].where, fmt::format("parts[{}].fem.rigid_walls[{}]", part, k),
                         fmt::format("node {} starts behind the wall (its normal points to the "
                                     "part's side)",
                                     n));
    walls.push_back(w);
  }
  return walls;
}

/// Holds a node (position x, velocity v about to move it by dt v, mass m, its acceleration a of
/// the half kick that gave v) off the walls; returns the walls' work on it. A node already behind
/// a wall is not pushed out.
///
/// The work is the one the leapfrog's energy balance needs: a velocity change dv at the half step
/// (v_pre -> v') changes the full-step kinetic energy by (m/2) dv . (v^n + v^{n+1}) less what the
/// forces' trapezoidal work (crater books dt v' . f) already counts, which leaves
/// (m/2) dv . (v' + v_pre - dt a). A first impact gives (m/2)(|v'|^2 - |v_pre|^2), the kinetic
/// energy the node loses; a node resting on the wall under a steady force gives 0 (its velocity
/// is kicked in and held back every step, and no energy goes anywhere).
template <int D>
Real hold_off_walls(const std::vector<RigidWall<D>>& walls, const Vec<D>& x, Vec<D>& v, Real m,
                    Real dt, const Vec<D>& a) {
  const Vec<D> before = v;
  for (const RigidWall<D>& w : walls) {
    const Real gap = (x - w.point).dot(w.normal);
    const Real vn = v.dot(w.normal);
    const Real lowest = gap > 0 ? -gap / dt : Real(0);  // the inward speed that just lands
    if (vn >= lowest) continue;
    const Real dvn = lowest - vn;  // > 0
    v += dvn * w.normal;
    if (w.friction > 0) {
      const Vec<D> vt = v - v.dot(w.normal) * w.normal;
      const Real speed = vt.norm();
      if (speed > 0) v -= std::min(speed, w.friction * dvn) / speed * vt;
    }
  }
  return Real(0.5) * m * (v - before).dot(v + before - dt * a);
}

/// Lysmer-Kuhlemeyer dashpots on the boundary faces `faces` (reference configuration): per node,
/// the index of its damping matrix (dashpot_of_node, -1: none) and the matrices.
template <int D, class Faces>
void add_dashpots(const Faces& faces, const materials::ElasticParams& el, Real rho,
                  std::vector<Index>& dashpot_of_node, std::vector<MatD<D>>& matrices) {
  const Real cp = std::sqrt(materials::p_wave_modulus(el) / rho);
  const Real cs = std::sqrt(materials::shear_modulus(el) / rho);
  for (const auto& face : faces) {
    const Vec<D> n = face.unit_normal;
    const MatD<D> nn = n * n.transpose();
    const MatD<D> c = (face.area / Real(face.nodes.size())) *
                      (rho * cp * nn + rho * cs * (MatD<D>::Identity() - nn));
    for (Index node : face.nodes) {
      Index& d = dashpot_of_node[static_cast<std::size_t>(node)];
      if (d < 0) {
        d = static_cast<Index>(matrices.size());
        matrices.push_back(MatD<D>::Zero());
      }
      matrices[static_cast<std::size_t>(d)] += c;
    }
  }
}

}  // namespace crater::fem
