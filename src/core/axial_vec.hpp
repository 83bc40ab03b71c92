// Vector algebra of axial vectors (angular velocities, torques, moments), shared by the DEM
// contact laws (src/dem/laws/) and the contacts between parts (src/contact/). An AxialVec<D>
// (core/types.hpp) is one component \omega_3 about the out-of-plane axis in 2D, a 3-vector in
// 3D.
#pragma once

#include <Eigen/Geometry>  // Vec<3>::cross

#include "core/types.hpp"

namespace crater {

/// Zero of AxialVec<D> (Eigen's default constructor leaves a Vec<3> uninitialised).
template <int D>
inline AxialVec<D> axial_zero() {
  if constexpr (D == 2) {
    return Real(0);
  } else {
    return AxialVec<D>::Zero();
  }
}

/// \omega \times r: the velocity of the point at arm r from the centre of a body spinning at
/// \omega. In 2D, \omega = \omega_3 e_z and r in the plane: (-\omega_3 r_y, \omega_3 r_x).
template <int D>
inline Vec<D> spin_cross(const AxialVec<D>& omega, const Vec<D>& r) {
  if constexpr (D == 2) {
    return Vec<2>(-omega * r.y(), omega * r.x());
  } else {
    return omega.cross(r);
  }
}

/// Moment r \times F of force F at arm r. In 2D the out-of-plane component r_x F_y - r_y F_x.
template <int D>
inline AxialVec<D> moment_of(const Vec<D>& r, const Vec<D>& f) {
  if constexpr (D == 2) {
    return r.x() * f.y() - r.y() * f.x();
  } else {
    return r.cross(f);
  }
}

}  // namespace crater
