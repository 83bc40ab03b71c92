// Where a point meets a face of a solid's surface (parts::ContactSurface): the closest point of
// the face with the weights of its nodes there, and the face's outward normal. Used by the
// particle-surface and surface-surface pairings.
#pragma once

#include <Eigen/Geometry>  // Vec<3>::cross
#include <algorithm>
#include <array>

#include "core/types.hpp"
#include "parts/part.hpp"

namespace crater::contact {

/// Closest point of a face to x, with the weights of the face's nodes at it.
template <int D>
struct FacePoint {
  Vec<D> point = Vec<D>::Zero();
  std::array<Real, parts::kFaceNodes<D>> weight{};
};

/// Closest point of triangle (a, b, c) to p, as barycentric weights (Ericson, Real-Time
/// Collision Detection, 2005, section 5.1.5).
inline std::array<Real, 3> closest_on_triangle(const Vec<3>& p, const Vec<3>& a, const Vec<3>& b,
                                               const Vec<3>& c) {
  const Vec<3> ab = b - a, ac = c - a, ap = p - a;
  const Real d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
  const Vec<3> bp = p - b;
  const Real d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
  const Real vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const Real v = d1 / (d1 - d3);
    return {1 - v, v, 0};
  }
  const Vec<3> cp = p - c;
  const Real d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
  const Real vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const Real w = d2 / (d2 - d6);
    return {1 - w, 0, w};
  }
  const Real va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const Real w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - w, w};
  }
  const Real denom = 1 / (va + vb + vc);
  const Real v = vb * denom, w = vc * denom;
  return {1 - v - w, v, w};
}

/// Closest point to p of the face with nodes x: a segment (2D), or a quadrilateral taken as
/// the triangles (0, 1, 2) and (0, 2, 3) (3D).
template <int D>
FacePoint<D> closest_on_face(const Vec<D>& p, const std::array<Vec<D>, parts::kFaceNodes<D>>& x) {
  FacePoint<D> fp;
  if constexpr (D == 2) {
    const Vec<D> t = x[1] - x[0];
    const Real len2 = t.squaredNorm();
    const Real s = len2 > 0 ? std::clamp((p - x[0]).dot(t) / len2, Real(0), Real(1)) : Real(0);
    fp.weight = {1 - s, s};
    fp.point = x[0] + s * t;
  } else {
    // The nearer triangle's point.
    const auto w1 = closest_on_triangle(p, x[0], x[1], x[2]);
    const auto w2 = closest_on_triangle(p, x[0], x[2], x[3]);
    const Vec<3> c1 = w1[0] * x[0] + w1[1] * x[1] + w1[2] * x[2];
    const Vec<3> c2 = w2[0] * x[0] + w2[1] * x[2] + w2[2] * x[3];
    if ((p - c1).squaredNorm() <= (p - c2).squaredNorm()) {
      fp.point = c1;
      fp.weight = {w1[0], w1[1], w1[2], 0};
    } else {
      fp.point = c2;
      fp.weight = {w2[0], 0, w2[1], w2[2]};
    }
  }
  return fp;
}

/// Outward unit normal of a face (numbering of parts::ContactSurface).
template <int D>
Vec<D> face_normal(const std::array<Vec<D>, parts::kFaceNodes<D>>& x) {
  Vec<D> n;
  if constexpr (D == 2) {
    const Vec<D> t = x[1] - x[0];
    n = Vec<D>(t[1], -t[0]);
  } else {
    n = (x[2] - x[0]).cross(x[3] - x[1]);
  }
  const Real len = n.norm();
  return len > 0 ? Vec<D>(n / len) : Vec<D>::Zero();
}

}  // namespace crater::contact
