// The Love–Weber stress of one grain ([L27], [W66]; [CMN81], [B96] for granular assemblies):
//   \sigma_i = (1/V_i) \sum_c \mathrm{sym}((\mathbf x_c - \mathbf x_i) \otimes \mathbf f_c)   [Pa]
// over grain i's contacts c, \mathbf x_c the contact point [m], \mathbf f_c the force the contact
// exerts ON grain i [N]. Tension is positive, as the FE stresses (a grain squeezed by its
// neighbours has \sigma < 0: an arm x_c - x_i pointing at a neighbour meets a force pointing
// back). It is the grain's mean stress, (1/V) \int \sigma dV = (1/V) \oint x \otimes t dS for a
// body loaded at points, whose body force (gravity) acts at its centre and adds nothing;
// the symmetric part, since the contacts' couples (rolling resistance, bond moments) and an
// unbalanced torque are not a stress.
// V_i is the grain's share of the bulk, V_grain / \phi with \phi the part's solid fraction, so
// that \sum_{i \in R} \sigma_i V_i / V_R is the mean stress of a region R of the bed ([B96]:
// the average stress of an assembly is the sum of the grains' moments over its volume).
// 2D: disks per metre of depth, forces per metre and V = \pi r^2 \times 1 m, as the part's; the
// tensor's z components stay zero.
//
// References
//   [L27]   A. E. H. Love, A Treatise on the Mathematical Theory of Elasticity, 4th ed.,
//           Cambridge University Press (1927), the mean stress of a body from its surface
//           tractions.
//   [W66]   J. Weber, "Recherches concernant les contraintes intergranulaires dans les milieux
//           pulvérulents", Bulletin de Liaison des Ponts et Chaussées 20 (1966) 1-20.
//   [CMN81] J. Christoffersen, M. M. Mehrabadi, S. Nemat-Nasser, "A micromechanical
//           description of granular material behavior", J. Appl. Mech. 48 (1981) 339-344.
//   [B96]   K. Bagi, "Stress and strain in granular assemblies", Mech. Mater. 22 (1996) 165-177.
#pragma once

#include "core/types.hpp"

namespace crater::dem {

/// One contact's term of the sum above, \mathrm{sym}(\mathbf a \otimes \mathbf f) [N m] (per
/// metre in 2D): arm a = x_c - x_i [m], f the force on grain i [N]; VTK's component order
/// (core/types.hpp: xx, yy, zz, xy, yz, xz).
template <int D>
inline SymTensor contact_moment(const Vec<D>& arm, const Vec<D>& force) {
  SymTensor s = SymTensor::Zero();
  s[0] = arm[0] * force[0];
  s[1] = arm[1] * force[1];
  s[3] = Real(0.5) * (arm[0] * force[1] + arm[1] * force[0]);
  if constexpr (D == 3) {
    s[2] = arm[2] * force[2];
    s[4] = Real(0.5) * (arm[1] * force[2] + arm[2] * force[1]);
    s[5] = Real(0.5) * (arm[0] * force[2] + arm[2] * force[0]);
  }
  return s;
}

/// \sigma_i [Pa] from the sum of grain i's contact moments [N m] and its share of the bulk,
/// V_i = V_grain / \phi [m^3] (2D: m^2 x 1 m).
inline SymTensor grain_stress(const SymTensor& moment_sum, Real grain_volume, Real solid_fraction) {
  return (solid_fraction / grain_volume) * moment_sum;
}

}  // namespace crater::dem
