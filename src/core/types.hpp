// Basic numeric types shared by every module.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <type_traits>

namespace crater {

/// The floating-point type of all physics (STYLE habit 9: double until a profile says otherwise).
using Real = double;

/// Entity index inside one part (particles, nodes, elements).
using Index = std::int64_t;

/// Fixed-size spatial vector, D = 2 (plane strain) or D = 3.
template <int D>
using Vec = Eigen::Matrix<Real, D, 1>;

/// Dimension-independent integer cell coordinate.
template <int D>
using IVec = Eigen::Matrix<std::int64_t, D, 1>;

/// A symmetric tensor (a stress) as its six components in VTK's order xx, yy, zz, xy, yz, xz, the
/// order ParaView reads a 6-component array in; a 2D (plane) tensor leaves zz, yz and xz zero.
using SymTensor = Eigen::Matrix<Real, 6, 1>;

/// A moment or angular velocity: the z component in 2D (a scalar), a vector in 3D.
template <int D>
using AxialVec = std::conditional_t<D == 2, Real, Eigen::Matrix<Real, 3, 1>>;

/// x^(1/D): the side of a D-dimensional cube of measure x (sqrt in 2D, cbrt in 3D; cheaper and
/// exactly rounded where std::pow(x, 1.0 / D) is neither).
template <int D>
inline Real dth_root(Real x) {
  static_assert(D >= 1 && D <= 3);
  if constexpr (D == 1) {
    return x;
  } else if constexpr (D == 2) {
    return std::sqrt(x);
  } else {
    return std::cbrt(x);
  }
}

}  // namespace crater
