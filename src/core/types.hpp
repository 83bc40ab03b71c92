// Basic numeric types shared by every module.
#pragma once

#include <Eigen/Core>
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

/// A moment or angular velocity: the z component in 2D (a scalar), a vector in 3D.
template <int D>
using AxialVec = std::conditional_t<D == 2, Real, Eigen::Matrix<Real, 3, 1>>;

}  // namespace crater
