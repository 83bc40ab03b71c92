// The geometric searches of the pairings with a surface (particle_surface.hpp,
// surface_surface.hpp): which body touches which face, where, how deep. Each returns its hits
// in ascending body order, the same for any thread count.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "contact/candidates.hpp"
#include "contact/face_geometry.hpp"
#include "core/index.hpp"
#include "core/types.hpp"
#include "parts/part.hpp"

namespace crater::contact {

/// Largest particle radius [m] (-infinity when none), of the whole part. On one thread: a scan of a
/// few thousand radii costs about what a fork and join of the team would.
template <int D>
Real largest_radius(const parts::ContactPoints<D>& pts) {
  if (pts.whole_count >= 0) return pts.whole_largest_radius_m;         // a contact zone's view
  if (!std::isnan(pts.largest_radius_m)) return pts.largest_radius_m;  // kept by the part
  Real r = -std::numeric_limits<Real>::infinity();
  for (const Real ri : *pts.radius)
    r = std::max(r, ri);
  return r;
}

/// A body (a particle, or a node of another surface) against a face of a surface (face < 0:
/// none).
template <int D>
struct FaceHit {
  Index body = -1;  // the particle or the node
  Index face = -1;
  FacePoint<D> where;         // the closest point of the face, with its nodes' weights
  Vec<D> n = Vec<D>::Zero();  // contact normal: the face's outward one, towards the body
  Real overlap = 0;           // depth of the body behind the face [m]
  Real k = 0;                 // node against face: penalty stiffness without the scale [N/m]
};

/// The centres of a surface's faces, each face's largest distance of one of its nodes from its
/// centre, and the largest of those.
template <int D>
struct FaceCentres {
  std::vector<Vec<D>> centre;
  std::vector<Real> half;
  Real half_size = 0;
};
template <int D>
FaceCentres<D> face_centres(const parts::ContactSurface<D>& surf);

/// The particles that touch a face, ascending, each with its face of largest overlap (ties:
/// the lowest face); FaceHit::k is left 0 (the face's own stiffness serves). With `kept`, the
/// candidate faces come from the pairing's kept list (candidates.hpp); the hits are the same.
template <int D>
std::vector<FaceHit<D>> particle_face_hits(const parts::ContactPoints<D>& pts,
                                           const parts::ContactSurface<D>& surf,
                                           CrossCandidates<D>* kept = nullptr);
/// The same hits, with the candidates kept by the particles' ids (a large set, few near).
template <int D>
std::vector<FaceHit<D>> particle_face_hits(const parts::ContactPoints<D>& pts,
                                           const parts::ContactSurface<D>& surf,
                                           NearCandidates<D>& kept);

/// Every surface node of `nodes_of` that carries mass, ascending, with the face of `faces_of`
/// it is in contact with (face < 0: none) and the stiffer of the two sides' springs.
template <int D>
std::vector<FaceHit<D>> node_face_hits(const parts::ContactSurface<D>& nodes_of,
                                       const parts::ContactSurface<D>& faces_of);

}  // namespace crater::contact
