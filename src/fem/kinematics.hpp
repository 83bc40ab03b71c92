// Element kinematics of the explicit solid: velocity gradient, rate of deformation, spin, and
// the objective (Jaumann) stress rate.
//
//   L_{ij} = \sum_I v_{iI} b_{jI}   (uniform strain gradients, element_geometry.hpp)   [1/s]
//   d = (L + L^T)/2,   W = (L - L^T)/2
// In plane strain (D = 2) L is embedded in 3x3 with L_{i3} = L_{3i} = 0, so d_{33} = 0 and the
// material laws see \sigma_{33} evolve through the Poisson effect.
//
// Jaumann rate [BLM00 §5.4]: \sigma^{\nabla J} = \dot\sigma - W\sigma + \sigma W, i.e.
//   \dot\sigma = \sigma^{\nabla J} + W \sigma - \sigma W,
// with \sigma^{\nabla J} given by the constitutive law (hypoelastic: C : d). Integrated over a
// step with the incrementally objective rotation of Hughes & Winget [HW80]:
//   Q = (I - \Delta t W/2)^{-1} (I + \Delta t W/2),   \sigma^* = Q \sigma_n Q^T,
// exactly orthogonal (a rigid rotation leaves the stress invariants untouched at any step size)
// and equal to \sigma_n + \Delta t (W\sigma_n - \sigma_n W) to first order. The law then adds
// its increment from \Delta\varepsilon = d \Delta t.
//
// References
//   [HW80]  T. J. R. Hughes, J. Winget, "Finite rotation effects in numerical integration of
//           rate constitutive equations arising in large-deformation analysis", Int. J. Numer.
//           Meth. Eng. 15 (1980) 1862-1867.
//   [BLM00] T. Belytschko, W. K. Liu, B. Moran, "Nonlinear Finite Elements for Continua and
//           Structures", Wiley (2000), §5.4.
#pragma once

#include <Eigen/LU>

#include "core/types.hpp"
#include "fem/element_geometry.hpp"
#include "materials/strength/stress_tensor.hpp"

namespace crater::fem {

using materials::Mat3;

/// Mean velocity gradient L [1/s] of an element (3x3; zero third row/column in 2D).
template <int D>
inline Mat3 velocity_gradient(const NodeArray<D>& v, const UniformStrainGradients<D>& g) {
  Mat3 l = Mat3::Zero();
  for (int node = 0; node < kElementNodes<D>; ++node) {
    l.template topLeftCorner<D, D>() += v[node] * g.b[node].transpose();
  }
  return l;
}

/// Rate of deformation d = sym(L) [1/s].
inline Mat3 rate_of_deformation(const Mat3& l) {
  return Real(0.5) * (l + l.transpose());
}

/// Spin W = skew(L) [1/s].
inline Mat3 spin(const Mat3& l) {
  return Real(0.5) * (l - l.transpose());
}

/// Stress rotated over one step by the Jaumann rate, Hughes-Winget form (header comment).
inline Mat3 jaumann_rotate(const Mat3& stress, const Mat3& w, Real dt) {
  const Mat3 half = Real(0.5) * dt * w;
  const Mat3 q = (Mat3::Identity() - half).inverse() * (Mat3::Identity() + half);
  return q * stress * q.transpose();
}

/// The same for a spin in the x-y plane only (2D: W = [[0, w01], [-w01, 0]]): there the
/// Hughes-Winget Q is the plane rotation with cos = (1 - a^2)/(1 + a^2), sin = 2a/(1 + a^2),
/// a = w01 dt / 2, written out (no 3x3 inverse and products: the 2D element loop's hot spot).
inline Mat3 jaumann_rotate_plane(const Mat3& stress, Real w01, Real dt) {
  const Real a = Real(0.5) * dt * w01;
  const Real inv = 1 / (1 + a * a);
  const Real c = (1 - a * a) * inv, s = 2 * a * inv;
  const Real xx = stress(0, 0), yy = stress(1, 1), xy = stress(0, 1);
  const Real xz = stress(0, 2), yz = stress(1, 2);
  Mat3 out;
  out(0, 0) = c * c * xx + 2 * c * s * xy + s * s * yy;
  out(1, 1) = s * s * xx - 2 * c * s * xy + c * c * yy;
  out(0, 1) = out(1, 0) = c * s * (yy - xx) + (c * c - s * s) * xy;
  out(0, 2) = out(2, 0) = c * xz + s * yz;
  out(1, 2) = out(2, 1) = c * yz - s * xz;
  out(2, 2) = stress(2, 2);
  return out;
}

}  // namespace crater::fem
