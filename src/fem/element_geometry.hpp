// Geometry of the one-point (uniform strain) quadrilateral (D = 2, plane strain, Q4) and
// hexahedron (D = 3, Hex8) of Flanagan & Belytschko [FB81]: mean shape-function gradients,
// volume, orthogonal hourglass shape vectors, characteristic length.
//
// Node numbering (as VTK_QUAD / VTK_HEXAHEDRON and LS-DYNA): reference coordinates
// \xi_I \in {-1, +1}^D, Q4 counter-clockwise (--, +-, ++, -+); Hex8 the same on the bottom
// face \zeta = -1 (nodes 0-3) then on the top face (4-7).
//
// Uniform strain gradients [FB81 eqs. 14-16]: the gradient operator averaged over the element,
//   b_{iI} = (1/V) \int_V N_{I,i} dV = (1/V) \partial V / \partial x_{iI}              [1/m]
// so the mean velocity gradient is exactly L_{ij} = \sum_I v_{iI} b_{jI} and the element
// reproduces any linear field (\sum_I x_{jI} b_{iI} = \delta_{ij}, \sum_I b_{iI} = 0).
//   Q4:   2A \partial A/\partial x_I: (y_2 - y_4, y_3 - y_1, y_4 - y_2, y_1 - y_3) (1-based), etc.
//   Hex8: \partial V/\partial x_1 = (1/12)[y_2((z_6 - z_3) - (z_4 - z_5)) + y_3(z_2 - z_4)
//          + y_4((z_3 - z_8) - (z_5 - z_2)) + y_5((z_8 - z_6) - (z_2 - z_4))
//          + y_6(z_5 - z_2) + y_8(z_4 - z_5)],
//         other nodes by the node permutation of [FB81] Table 1, other components by the
//         cyclic permutation x -> y -> z; V = \sum_I x_I \partial V/\partial x_I exactly.
// Hourglass shape vectors [FB81 eq. 60]: with the base vectors \Gamma_\alpha (the products
// \xi\eta for Q4; \eta\zeta, \zeta\xi, \xi\eta, \xi\eta\zeta for Hex8 at the nodes),
//   \gamma_{\alpha I} = \Gamma_{\alpha I} - (\sum_J \Gamma_{\alpha J} x_{iJ}) b_{iI},
// orthogonal to every linear velocity field, so hourglass forces never resist a uniform strain
// (the patch test holds on distorted meshes).
// Characteristic length from the [FB81] bound on the element's largest frequency,
//   \omega_{max}^2 <= n c^2 \sum_I b_{iI} b_{iI}  (n nodes),  \Delta t_{crit} = 2/\omega_{max},
//   L_e = 2 / \sqrt{n \sum_I b_{iI} b_{iI}},   \Delta t = L_e / c_d.
// A square of side h gives L_e = h/\sqrt2, a cube h/\sqrt3 (the uniform-strain element's
// dilatational mode); LS-DYNA's V / A_{max} face would give h, which is not a bound.
//
// References
//   [FB81] D. P. Flanagan, T. Belytschko, "A uniform strain hexahedron and quadrilateral with
//          orthogonal hourglass control", Int. J. Numer. Meth. Eng. 17 (1981) 679-706.
//   [BLM00] T. Belytschko, W. K. Liu, B. Moran, "Nonlinear Finite Elements for Continua and
//          Structures", Wiley (2000), §8.7 (one-point quadrature, hourglass control).
#pragma once

#include <array>
#include <cmath>

#include "core/types.hpp"

namespace crater::fem {

/// Nodes of the element of dimension D: 4 (Q4) or 8 (Hex8).
template <int D>
inline constexpr int kElementNodes = D == 2 ? 4 : 8;

/// Independent hourglass modes per direction: 1 (Q4) or 4 (Hex8).
template <int D>
inline constexpr int kHourglassModes = D == 2 ? 1 : 4;

/// One value per element node (positions, velocities, gradients, forces).
template <int D>
using NodeArray = std::array<Vec<D>, kElementNodes<D>>;

/// Global node ids of one element, in the numbering above.
template <int D>
using ElementNodes = std::array<Index, kElementNodes<D>>;

/// Hourglass vectors, one row per mode, one column per node.
template <int D>
using HourglassVectors = Eigen::Matrix<Real, kHourglassModes<D>, kElementNodes<D>>;

/// Reference coordinate \xi_{I,k} in {-1, +1} of node I along axis k.
template <int D>
constexpr Real reference_sign(int node, int axis) {
  // Q4 / each Hex8 face: (--, +-, ++, -+); Hex8 top face for nodes 4-7.
  constexpr int kX[4] = {-1, 1, 1, -1};
  constexpr int kY[4] = {-1, -1, 1, 1};
  if (axis == 0) {
    return Real(kX[node % 4]);
  }
  if (axis == 1) {
    return Real(kY[node % 4]);
  }
  return node < 4 ? Real(-1) : Real(1);
}

/// Mean gradients b_I [1/m] and volume V [m^3] (area per metre of depth in 2D) of an element.
template <int D>
struct UniformStrainGradients {
  NodeArray<D> b;
  Real volume = 0;
};

namespace detail {

/// [FB81] node permutation: row I relabels the nodes so that the node-1 formula gives node I.
inline constexpr int kHexPermutation[8][8] = {{0, 1, 2, 3, 4, 5, 6, 7}, {1, 2, 3, 0, 5, 6, 7, 4},
                                              {2, 3, 0, 1, 6, 7, 4, 5}, {3, 0, 1, 2, 7, 4, 5, 6},
                                              {4, 7, 6, 5, 0, 3, 2, 1}, {5, 4, 7, 6, 1, 0, 3, 2},
                                              {6, 5, 4, 7, 2, 1, 0, 3}, {7, 6, 5, 4, 3, 2, 1, 0}};

/// 12 \partial V / \partial x_I for node I from the y and z coordinates (FB81, node 1 formula).
inline Real hex_volume_derivative_12(const std::array<Real, 8>& y, const std::array<Real, 8>& z,
                                     int node) {
  const int* p = kHexPermutation[node];
  const Real y2 = y[p[1]];
  const Real y3 = y[p[2]];
  const Real y4 = y[p[3]];
  const Real y5 = y[p[4]];
  const Real y6 = y[p[5]];
  const Real y8 = y[p[7]];
  const Real z2 = z[p[1]];
  const Real z3 = z[p[2]];
  const Real z4 = z[p[3]];
  const Real z5 = z[p[4]];
  const Real z6 = z[p[5]];
  const Real z8 = z[p[7]];
  return y2 * ((z6 - z3) - (z4 - z5)) + y3 * (z2 - z4) + y4 * ((z3 - z8) - (z5 - z2)) +
         y5 * ((z8 - z6) - (z2 - z4)) + y6 * (z5 - z2) + y8 * (z4 - z5);
}

}  // namespace detail

/// Uniform strain gradients and volume of the element with nodal positions x [m].
template <int D>
inline UniformStrainGradients<D> uniform_strain_gradients(const NodeArray<D>& x) {
  UniformStrainGradients<D> g;
  if constexpr (D == 2) {
    const Real x13 = x[0].x() - x[2].x();
    const Real x24 = x[1].x() - x[3].x();
    const Real y13 = x[0].y() - x[2].y();
    const Real y24 = x[1].y() - x[3].y();
    // 2A = (x3 - x1)(y4 - y2) + (x2 - x4)(y3 - y1)  (1-based)
    const Real two_area = x13 * y24 - x24 * y13;
    g.volume = Real(0.5) * two_area;
    const Real inv = Real(1) / two_area;
    g.b[0] = Vec<2>(y24, -x24) * inv;
    g.b[1] = Vec<2>(-y13, x13) * inv;
    g.b[2] = Vec<2>(-y24, x24) * inv;
    g.b[3] = Vec<2>(y13, -x13) * inv;
  } else {
    std::array<Real, 8> cx;
    std::array<Real, 8> cy;
    std::array<Real, 8> cz;
    for (int i = 0; i < 8; ++i) {
      cx[i] = x[i].x();
      cy[i] = x[i].y();
      cz[i] = x[i].z();
    }
    NodeArray<3> dv;  // 12 dV/dx_I
    for (int i = 0; i < 8; ++i) {
      dv[i] = Vec<3>(detail::hex_volume_derivative_12(cy, cz, i),
                     detail::hex_volume_derivative_12(cz, cx, i),
                     detail::hex_volume_derivative_12(cx, cy, i));
    }
    Real v12 = 0;
    for (int i = 0; i < 8; ++i) {
      v12 += cx[i] * dv[i].x();
    }
    g.volume = v12 / Real(12);
    const Real inv = Real(1) / v12;
    for (int i = 0; i < 8; ++i) {
      g.b[i] = dv[i] * inv;
    }
  }
  return g;
}

/// Hourglass base vectors \Gamma_\alpha (products of reference coordinates at the nodes).
template <int D>
inline HourglassVectors<D> hourglass_base_vectors() {
  HourglassVectors<D> gamma;
  for (int node = 0; node < kElementNodes<D>; ++node) {
    const Real xi = reference_sign<D>(node, 0);
    const Real eta = reference_sign<D>(node, 1);
    if constexpr (D == 2) {
      gamma(0, node) = xi * eta;
    } else {
      const Real zeta = reference_sign<D>(node, 2);
      gamma(0, node) = eta * zeta;
      gamma(1, node) = zeta * xi;
      gamma(2, node) = xi * eta;
      gamma(3, node) = xi * eta * zeta;
    }
  }
  return gamma;
}

/// Orthogonalised hourglass shape vectors \gamma_\alpha [FB81 eq. 60] (dimensionless).
template <int D>
inline HourglassVectors<D> hourglass_shape_vectors(const NodeArray<D>& x,
                                                   const UniformStrainGradients<D>& g) {
  const HourglassVectors<D> base = hourglass_base_vectors<D>();
  HourglassVectors<D> gamma = base;
  for (int a = 0; a < kHourglassModes<D>; ++a) {
    Vec<D> gx = Vec<D>::Zero();  // \sum_J \Gamma_{aJ} x_J
    for (int node = 0; node < kElementNodes<D>; ++node) {
      gx += base(a, node) * x[node];
    }
    for (int node = 0; node < kElementNodes<D>; ++node) {
      gamma(a, node) -= gx.dot(g.b[node]);
    }
  }
  return gamma;
}

/// Characteristic length L_e = 2 / \sqrt{n \sum_I |b_I|^2} [m] (see the header comment).
template <int D>
inline Real characteristic_length(const UniformStrainGradients<D>& g) {
  Real bb = 0;
  for (const Vec<D>& b : g.b) {
    bb += b.squaredNorm();
  }
  return Real(2) / std::sqrt(Real(kElementNodes<D>) * bb);
}

}  // namespace crater::fem
