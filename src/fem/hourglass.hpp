// Flanagan-Belytschko hourglass control of the one-point elements [FB81], viscous and stiffness
// forms (LS-DYNA hourglass types 3 and 5 [LSD]).
//
// Hourglass velocities, one per direction i and mode \alpha (\gamma from element_geometry.hpp):
//   g_{i\alpha} = \sum_I v_{iI} \gamma_{\alpha I}                                         [m/s]
// Generalised hourglass forces Q_{i\alpha} and nodal forces (on the nodes):
//   viscous:   Q_{i\alpha} = a_v g_{i\alpha},              a_v = \kappa \rho c V^{(D-1)/D} / 4
//   stiffness: Q_{i\alpha}^{n+1} = Q_{i\alpha}^n + a_s \Delta t g_{i\alpha},
//                                                        a_s = \kappa \rho c^2 V^{(D-2)/D} / 4
//   f_{iI} = -\sum_\alpha Q_{i\alpha} \gamma_{\alpha I}                     [N] (N/m in 2D)
// with \rho c the element's current density and dilatational wave speed. The stiffness scale is
// the viscous one with the rate replaced by c/V^{1/D} times the hourglass displacement. \kappa is
// typically 0.1 for the viscous form (LS-DYNA's default QH) and 0.03-0.1 for the stiffness form.
// Work rate of the hourglass forces (energy put into hourglass control) P = \sum Q_{i\alpha}
// g_{i\alpha} [W]. The stiffness form keeps Q in the element (not rotated with the element:
// adequate for moderate rotations, as in [FB81]).
//
// References
//   [FB81] D. P. Flanagan, T. Belytschko, Int. J. Numer. Meth. Eng. 17 (1981) 679-706, §5.
//   [LSD]  LS-DYNA Theory Manual (LSTC/Ansys), "Hourglass control": a_h = Q_{hg} \rho V^{2/3}
//          c / 4 for the viscous forms.
#pragma once

#include <cmath>

#include "core/types.hpp"
#include "fem/element_geometry.hpp"

namespace crater::fem {

enum class HourglassForm { kViscous, kStiffness };

/// Hourglass control of a block: form and coefficient \kappa [-].
struct HourglassParams {
  HourglassForm form = HourglassForm::kViscous;
  Real coefficient = 0.1;
};

/// Generalised stiffness-form hourglass forces Q_{i\alpha} kept per element [N].
template <int D>
using HourglassState = Eigen::Matrix<Real, D, kHourglassModes<D>>;

template <int D>
struct HourglassForces {
  NodeArray<D> force;  // on each node [N]
  Real power_w = 0;    // \sum Q g, work rate into hourglass control [W]
};

/// Hourglass forces of one element. gamma: hourglass shape vectors; v: nodal velocities [m/s];
/// volume [m^3]; density [kg/m^3]; wave_speed c [m/s]; dt [s]; state: Q of the stiffness form.
template <int D>
inline HourglassForces<D> hourglass_forces(const HourglassParams& params,
                                           const HourglassVectors<D>& gamma, const NodeArray<D>& v,
                                           Real volume, Real density, Real wave_speed, Real dt,
                                           HourglassState<D>& state) {
  HourglassState<D> g = HourglassState<D>::Zero();
  for (int node = 0; node < kElementNodes<D>; ++node) {
    g += v[node] * gamma.col(node).transpose();
  }
  HourglassState<D> q;
  if (params.form == HourglassForm::kViscous) {
    // volume^((D-1)/D): a face's measure.
    const Real a =
        params.coefficient * density * wave_speed * (volume / dth_root<D>(volume)) / Real(4);
    q = a * g;
  } else {
    // volume^((D-2)/D): 1 in 2D, an edge's length in 3D.
    const Real edge = D == 2 ? Real(1) : dth_root<D>(volume);
    const Real a = params.coefficient * density * wave_speed * wave_speed * edge / Real(4);
    state += (a * dt) * g;
    q = state;
  }
  HourglassForces<D> out;
  for (int node = 0; node < kElementNodes<D>; ++node) {
    out.force[node] = -q * gamma.col(node);
  }
  out.power_w = q.cwiseProduct(g).sum();
  return out;
}

}  // namespace crater::fem
