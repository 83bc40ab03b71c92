// The searches of face_search.hpp.
#include "contact/face_search.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <utility>

#include "core/index.hpp"
#include "neighbors/neighbor_list.hpp"
#include "parallel/parallel.hpp"

namespace crater::contact {

template <int D>
FaceCentres<D> face_centres(const parts::ContactSurface<D>& surf) {
  constexpr int kF = parts::kFaceNodes<D>;
  const auto& xn = *surf.node_position;
  const auto& faces = *surf.faces;
  FaceCentres<D> out;
  const Index nf = static_cast<Index>(faces.size());
  out.centre.resize(at(nf));
  out.half.assign(at(nf), 0);
  parallel::for_each(nf, [&](Index f) {
    Vec<D> c = Vec<D>::Zero();
    for (Index n : faces[at(f)])
      c += xn[at(n)] / Real(kF);
    out.centre[at(f)] = c;
    for (Index n : faces[at(f)])
      out.half[at(f)] = std::max(out.half[at(f)], (xn[at(n)] - c).norm());
  });
  out.half_size = parallel::max_over(nf, out.half_size, [&](Index f) { return out.half[at(f)]; });
  return out;
}

// How far beside a face [in particle radii] a particle's centre behind the face's plane may
// project and still count as having crossed the face (round-off of the closest point: it is the
// projection itself when that lies on the face).
constexpr Real kBesideFace = 1e-6;

namespace {

// The face tests of the points near[k] against the faces of their rows row(k): of each point,
// the face of largest overlap, if any (the order of `near`).
template <int D, class Row>
std::vector<FaceHit<D>> face_tests(const parts::ContactPoints<D>& pts,
                                   const parts::ContactSurface<D>& surf, const FaceCentres<D>& fc,
                                   Real reach, std::span<const Index> near, Row&& row) {
  constexpr int kF = parts::kFaceNodes<D>;
  const auto& xn = *surf.node_position;
  const auto& faces = *surf.faces;
  const std::vector<Vec<D>>& centre = fc.centre;
  const Real reach_sq = reach * reach;  // the test of a list built for `reach`
  std::vector<FaceHit<D>> found(near.size());
  auto test = [&](Index k) {
    const Index i = near[at(k)];
    const Vec<D>& x = (*pts.position)[at(i)];
    const Real r = (*pts.radius)[at(i)];
    FaceHit<D> best;
    best.body = i;
    for (Index f : row(k)) {
      const Real d2 = search_distance_sq<D>(centre[at(f)], x);
      if (d2 > reach_sq) continue;  // a kept list's margin
      // A face the particle overlaps has its closest point within r of the centre and
      // within the face's own half size of its centre: the others cannot be the hit
      // (their overlap is not positive), so they are passed over before that work (the
      // factor covers the rounding of the distances).
      const Real own = (fc.half[at(f)] + r) * Real(1 + 1e-9);
      if (d2 > own * own) continue;
      std::array<Vec<D>, kF> fx;
      for (int q = 0; q < kF; ++q)
        fx[at(q)] = xn[at(faces[at(f)][at(q)])];
      const FacePoint<D> fp = closest_on_face<D>(x, fx);
      const Vec<D> nf_out = face_normal<D>(fx);
      const Vec<D> d = x - fp.point;
      const Real s = d.dot(nf_out);
      // Behind the face's plane but beside the face (a particle resting on a plate's top
      // next to its edge is behind the side face's plane) the centre has not crossed the
      // face: the particle meets its edge or corner from outside, as in front of it.
      const bool crossed = s < 0 && (d - s * nf_out).norm() <= kBesideFace * r;
      if (crossed && s <= -r)
        continue;  // beyond the reach of this face (e.g. the other side of a plate)
      Real overlap = 0;
      Vec<D> n;
      if (!crossed) {
        const Real dist = d.norm();
        overlap = r - dist;
        n = dist > 0 ? Vec<D>(d / dist) : nf_out;
      } else {
        overlap = r - s;
        n = nf_out;
      }
      if (overlap > best.overlap) {
        best.face = f;
        best.overlap = overlap;
        best.where = fp;
        best.n = n;
      }
    }
    found[at(k)] = best;
  };
  // Dealt out in blocks as threads come free: the points near the surface, with many candidate
  // faces, come in runs of the points' order.
  constexpr Index kBlock = 16;
  parallel::for_each_block(
      static_cast<Index>(near.size()), kBlock,
      [&](Index first, Index last) {
        for (Index k = first; k < last; ++k)
          test(k);
      },
      parallel::Cost::heavy);
  const std::vector<Index> touching = parallel::select(
      static_cast<Index>(found.size()), [&](Index k) { return found[at(k)].face >= 0; });
  std::vector<FaceHit<D>> touched(touching.size());
  for (std::size_t k = 0; k < touching.size(); ++k)
    touched[k] = found[at(touching[k])];
  return touched;
}

// Candidates: faces whose centre is within r_max + the largest face half-size.
template <int D>
Real face_reach(const parts::ContactPoints<D>& pts, const FaceCentres<D>& fc) {
  return largest_radius(pts) + fc.half_size;
}

}  // namespace

template <int D>
std::vector<FaceHit<D>> particle_face_hits(const parts::ContactPoints<D>& pts,
                                           const parts::ContactSurface<D>& surf,
                                           CrossCandidates<D>* kept) {
  const Index nf = static_cast<Index>(surf.faces->size());
  const Index np = static_cast<Index>(pts.position->size());
  if (nf == 0 || np == 0) return {};
  const FaceCentres<D> fc = face_centres(surf);
  const Real reach = face_reach(pts, fc);
  neighbors::NeighborList fresh;
  const std::span<const Vec<D>> xp(*pts.position);
  const std::span<const Vec<D>> xc(fc.centre);
  if (!kept) neighbors::build_cross_list<D>(xp, xc, reach, fresh);
  const neighbors::NeighborList& candidates =
      kept ? kept->find(xp, numbering(pts), xc,
                        Numbering{.ids = {}, .revision = surf.revision, .known = true}, reach)
           : fresh;
  // Only the particles with a candidate face (a few per cent of a soil bed) are looked at.
  const std::vector<Index> near =
      parallel::select(np, [&](Index i) { return !candidates.of(i).empty(); });
  return face_tests(pts, surf, fc, reach, std::span<const Index>(near),
                    [&](Index k) { return candidates.of(near[at(k)]); });
}

template <int D>
std::vector<FaceHit<D>> particle_face_hits(const parts::ContactPoints<D>& pts,
                                           const parts::ContactSurface<D>& surf,
                                           NearCandidates<D>& kept) {
  const Index nf = static_cast<Index>(surf.faces->size());
  const Index np = static_cast<Index>(pts.position->size());
  if (nf == 0 || np == 0) return {};
  const FaceCentres<D> fc = face_centres(surf);
  const Real reach = face_reach(pts, fc);
  const NearRows& rows = kept.find(
      std::span<const Vec<D>>(*pts.position), numbering(pts), std::span<const Vec<D>>(fc.centre),
      Numbering{.ids = {}, .revision = surf.revision, .known = true}, reach);
  return face_tests(pts, surf, fc, reach, std::span<const Index>(rows.point),
                    [&](Index k) { return rows.of(at(k)); });
}

template <int D>
std::vector<FaceHit<D>> node_face_hits(const parts::ContactSurface<D>& nodes_of,
                                       const parts::ContactSurface<D>& faces_of) {
  constexpr int kF = parts::kFaceNodes<D>;
  const auto& xa = *nodes_of.node_position;
  const auto& xb = *faces_of.node_position;
  const auto& faces = *faces_of.faces;
  // The surface nodes of `nodes_of` that carry mass, ascending, with the stiffest of their
  // own faces: from its faces, not from every node of the part (most are inside).
  std::vector<std::pair<Index, Real>> own;
  own.reserve(nodes_of.faces->size() * kF);
  for (std::size_t f = 0; f < nodes_of.faces->size(); ++f)
    for (Index n : (*nodes_of.faces)[f])
      own.emplace_back(n, (*nodes_of.face_stiffness)[f]);
  std::sort(own.begin(), own.end());  // a node's faces together, its stiffest last
  std::vector<Index> nodes;
  std::vector<Real> node_k;
  for (std::size_t q = 0; q < own.size(); ++q) {
    if (q + 1 < own.size() && own[q + 1].first == own[q].first) continue;
    const auto [n, k] = own[q];
    if (k > 0 && (*nodes_of.node_mass)[at(n)] > 0) {
      nodes.push_back(n);
      node_k.push_back(k);
    }
  }
  std::vector<FaceHit<D>> hits(nodes.size());
  const Index nf = static_cast<Index>(faces.size());
  if (nf == 0 || nodes.empty()) return hits;

  const FaceCentres<D> fc = face_centres(faces_of);
  const std::vector<Vec<D>>& centre = fc.centre;
  const Real half_size = fc.half_size;
  std::vector<Real> size(at(nf)), reach2(at(nf));
  for (Index f = 0; f < nf; ++f) {
    std::array<Vec<D>, kF> fx;
    Real own_half = 0;
    for (int k = 0; k < kF; ++k) {
      fx[at(k)] = xb[at(faces[at(f)][at(k)])];
      own_half = std::max(own_half, (fx[at(k)] - centre[at(f)]).norm());
    }
    if constexpr (D == 2) {
      size[at(f)] = (fx[1] - fx[0]).norm();
    } else {
      size[at(f)] = std::sqrt(Real(0.5) * (fx[2] - fx[0]).cross(fx[3] - fx[1]).norm());
    }
    // A node the face takes (below) is within 0.51 of its size of the face's closest point,
    // which lies within the face's own half size of its centre: the candidates of a large
    // neighbour's reach that are further off are passed over (the same hits, less work).
    const Real r = own_half + Real(0.51) * size[at(f)];
    reach2[at(f)] = r * r;
  }
  std::vector<Vec<D>> x(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i)
    x[i] = xa[at(nodes[i])];
  // A node within half a face's size behind it, projecting onto it, is within
  // sqrt(half_size^2 + (half_size)^2) of its centre.
  neighbors::NeighborList candidates;
  neighbors::build_cross_list<D>(std::span<const Vec<D>>(x), std::span<const Vec<D>>(centre),
                                 Real(1.5) * half_size, candidates);
  parallel::for_each(
      static_cast<Index>(nodes.size()),
      [&](Index i) {
        FaceHit<D> best;
        best.body = nodes[at(i)];
        const Vec<D>& p = x[at(i)];
        for (Index f : candidates.of(i)) {
          if ((p - centre[at(f)]).squaredNorm() > reach2[at(f)]) continue;
          std::array<Vec<D>, kF> fx;
          for (int k = 0; k < kF; ++k)
            fx[at(k)] = xb[at(faces[at(f)][at(k)])];
          const FacePoint<D> fp = closest_on_face<D>(p, fx);
          const Vec<D> nf_out = face_normal<D>(fx);
          const Vec<D> d = p - fp.point;
          const Real s = d.dot(nf_out);
          const Real len = size[at(f)];
          if (s >= 0 || -s > Real(0.5) * len) continue;
          if ((d - s * nf_out).norm() > Real(0.01) * len) continue;  // projects beside the face
          if (best.face >= 0 && (-s > best.overlap || (-s == best.overlap && f > best.face)))
            continue;
          best.face = f;
          best.where = fp;
          best.n = nf_out;
          best.overlap = -s;
          best.k = std::min((*faces_of.face_stiffness)[at(f)], node_k[at(i)]);
        }
        hits[at(i)] = best;
      },
      parallel::Cost::heavy);
  return hits;
}

#define CRATER_FACE_SEARCH(D)                                                                \
  template FaceCentres<D> face_centres<D>(const parts::ContactSurface<D>&);                  \
  template std::vector<FaceHit<D>> particle_face_hits<D>(                                    \
      const parts::ContactPoints<D>&, const parts::ContactSurface<D>&, CrossCandidates<D>*); \
  template std::vector<FaceHit<D>> particle_face_hits<D>(                                    \
      const parts::ContactPoints<D>&, const parts::ContactSurface<D>&, NearCandidates<D>&);  \
  template std::vector<FaceHit<D>> node_face_hits<D>(const parts::ContactSurface<D>&,        \
                                                     const parts::ContactSurface<D>&);
CRATER_FACE_SEARCH(2)
CRATER_FACE_SEARCH(3)
#undef CRATER_FACE_SEARCH

}  // namespace crater::contact
