// Particles against a solid's surface; see particle_surface.hpp and coupling.hpp.
#include "contact/particle_surface.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>

#include "contact/penalty.hpp"
#include "core/axial_vec.hpp"
#include "neighbors/neighbor_list.hpp"
#include "parallel/parallel.hpp"

namespace crater::contact {

template <int D>
void ParticleSurface<D>::limit_step(const PartList<D>& parts, StepSearch& search) const {
  const auto pts = parts[points_]->contact_points();
  if (!pts || pts->mass->empty()) return;
  const Real m_min = lightest_particle(*pts);
  const auto surf = parts[other_]->contact_surface();
  if (!surf || surf->face_stiffness->empty()) return;
  const Real k_max = settings_.penalty_scale *
                     *std::max_element(surf->face_stiffness->begin(), surf->face_stiffness->end());
  // The spring joins the particle to a face node, which may be the lighter of the two.
  const Real node_min = lightest_face_node(*surf);
  search.consider(
      spring_step(k_max, reduced_mass(m_min, node_min), settings_.damping_ratio), -1, [&] {
        return fmt::format("contact '{}': penalty spring of stiffness {:.3g} N/m", name_, k_max);
      });
  // Bodies pressed by several springs at once (found afresh when particles were removed
  // since the last apply(): the cached sums are per particle index).
  if (!load_.known || load_.points.size() != pts->mass->size() ||
      load_.other.size() != surf->node_mass->size())
    measure_load(parts);
  this->limit_by_summed_springs(search, load_.points, *pts->mass, "particle");
  this->limit_by_summed_springs(search, load_.other, *surf->node_mass, "surface node");
}

template <int D>
std::vector<typename ParticleSurface<D>::Hit> ParticleSurface<D>::hits(
    const parts::ContactPoints<D>& pts, const parts::ContactSurface<D>& surf) {
  constexpr int kF = parts::kFaceNodes<D>;
  const auto& xn = *surf.node_position;
  const auto& faces = *surf.faces;
  const Index nf = static_cast<Index>(faces.size());
  const Index np = static_cast<Index>(pts.position->size());
  if (nf == 0 || np == 0) return {};

  // Candidates: faces whose centre is within r_max + the largest face half-size.
  std::vector<Vec<D>> centre(at(nf));
  Real half_size = 0;
  for (Index f = 0; f < nf; ++f) {
    Vec<D> c = Vec<D>::Zero();
    for (Index n : faces[at(f)])
      c += xn[at(n)] / Real(kF);
    centre[at(f)] = c;
    for (Index n : faces[at(f)])
      half_size = std::max(half_size, (xn[at(n)] - c).norm());
  }
  const Real r_max = *std::max_element(pts.radius->begin(), pts.radius->end());
  neighbors::NeighborList candidates;
  neighbors::build_cross_list<D>(std::span<const Vec<D>>(*pts.position),
                                 std::span<const Vec<D>>(centre), r_max + half_size, candidates);
  // Only the particles with a candidate face (a few per cent of a soil bed) are looked at.
  const std::vector<Index> near =
      parallel::select(np, [&](Index i) { return !candidates.of(i).empty(); });
  std::vector<Hit> found(near.size());
  parallel::for_each(static_cast<Index>(near.size()), [&](Index k) {
    const Index i = near[at(k)];
    const Vec<D>& x = (*pts.position)[at(i)];
    const Real r = (*pts.radius)[at(i)];
    Hit best;
    best.particle = i;
    for (Index f : candidates.of(i)) {
      std::array<Vec<D>, kF> fx;
      for (int q = 0; q < kF; ++q)
        fx[at(q)] = xn[at(faces[at(f)][at(q)])];
      const FacePoint<D> fp = closest_on_face<D>(x, fx);
      const Vec<D> nf_out = face_normal<D>(fx);
      const Vec<D> d = x - fp.point;
      const Real s = d.dot(nf_out);
      Real overlap = 0;
      Vec<D> n;
      if (s >= 0) {
        const Real dist = d.norm();
        overlap = r - dist;
        n = dist > 0 ? Vec<D>(d / dist) : nf_out;
      } else {
        if (s <= -r) continue;  // beyond the reach of this face (e.g. the other side of a plate)
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
  });
  const std::vector<Index> touching = parallel::select(
      static_cast<Index>(found.size()), [&](Index k) { return found[at(k)].face >= 0; });
  std::vector<Hit> touched(touching.size());
  for (std::size_t k = 0; k < touching.size(); ++k)
    touched[k] = found[at(touching[k])];
  return touched;
}

template <int D>
Real ParticleSurface<D>::stiffness(const parts::ContactSurface<D>& surf, Index face) const {
  return settings_.penalty_scale * (*surf.face_stiffness)[at(face)];
}

template <int D>
void ParticleSurface<D>::add_load(const parts::ContactSurface<D>& surf, const Hit& h) const {
  const Real k = stiffness(surf, h.face);
  load_.points[at(h.particle)] += k;
  const auto& face = (*surf.faces)[at(h.face)];
  for (int q = 0; q < parts::kFaceNodes<D>; ++q)
    load_.other[at(face[at(q)])] += k * h.where.weight[at(q)];
}

template <int D>
void ParticleSurface<D>::measure_load(const PartList<D>& parts) const {
  const auto pts = parts[points_]->contact_points();
  load_.points.assign(pts->position->size(), 0);
  const auto surf = parts[other_]->contact_surface();
  load_.other.assign(surf->node_position->size(), 0);
  for (const Hit& h : hits(*pts, *surf))
    add_load(*surf, h);
  load_.known = true;
}

template <int D>
std::vector<typename ParticleSurface<D>::Push> ParticleSurface<D>::pushes(
    const std::vector<Hit>& hits, Real dt, const parts::ContactPoints<D>& pts,
    const parts::ContactSurface<D>& surf) const {
  constexpr int kF = parts::kFaceNodes<D>;
  const auto& faces = *surf.faces;
  const Index np = static_cast<Index>(pts.position->size());
  const bool offsets = pts.surface_offset && pts.surface_overlap;
  if (offsets) {
    // A particle touching no face has no offset (it starts afresh at its next touch).
    std::vector<char> touching(at(np), 0);
    for (const Hit& h : hits)
      touching[at(h.particle)] = 1;
    parallel::for_each(np, [&](Index i) {
      if (!touching[at(i)]) (*pts.surface_offset)[at(i)] = -1;
    });
  }
  std::vector<Push> push(hits.size());
  parallel::for_each(static_cast<Index>(hits.size()), [&](Index q) {
    const Hit& h = hits[at(q)];
    const Index i = h.particle;
    const auto& face = faces[at(h.face)];
    Real m_face = 0;
    Vec<D> v_face = Vec<D>::Zero();
    for (int k = 0; k < kF; ++k) {
      m_face += h.where.weight[at(k)] * (*surf.node_mass)[at(face[at(k)])];
      v_face += h.where.weight[at(k)] * (*surf.node_velocity)[at(face[at(k)])];
    }
    Vec<D> v = (*pts.velocity)[at(i)];
    const Real r = (*pts.radius)[at(i)];
    const Vec<D> arm = -r * h.n;
    if (pts.angular_velocity) v += spin_cross<D>((*pts.angular_velocity)[at(i)], arm);
    Real pushed = h.overlap;
    if (offsets) {
      Real* offset = &(*pts.surface_offset)[at(i)];
      const Real approach = std::abs((v - v_face).dot(h.n)) * dt;
      Real& last = (*pts.surface_overlap)[at(i)];
      if (*offset < 0) {
        // First touch: what the approach over the step cannot explain is ignored.
        *offset = std::max(Real(0), h.overlap - approach);
      } else {
        // In contact already: a jump of the overlap beyond twice the approach is a face that
        // appeared under the particle (the element in front of it eroded) or a deeper face
        // taking over; it joins the offset. (Twice: the approach is measured with the
        // velocity at the end of the step, the overlap grew with the one inside it.)
        *offset += std::max(Real(0), h.overlap - last - 2 * approach);
        *offset = std::min(*offset, h.overlap);
      }
      last = h.overlap;
      pushed = h.overlap - *offset;
    }
    Push& out = push[at(q)];
    out.force = penalty_force<D>(stiffness(surf, h.face), pushed, h.n, v - v_face,
                                 reduced_mass((*pts.mass)[at(i)], m_face), settings_.damping_ratio,
                                 settings_.friction, out.normal);
  });
  return push;
}

template <int D>
void ParticleSurface<D>::apply(const PartList<D>& parts, Real dt_s, ContactForces<D>& out) {
  constexpr int kF = parts::kFaceNodes<D>;
  const auto pts = parts[points_]->contact_points();
  const auto surf = parts[other_]->contact_surface();
  const auto& faces = *surf->faces;
  const Index np = static_cast<Index>(pts->position->size());
  this->restart(at(np), surf->node_position->size());
  load_.known = true;
  if (faces.empty() || np == 0) return;

  const std::vector<Hit> touched = hits(*pts, *surf);
  const std::vector<Push> push = pushes(touched, dt_s, *pts, *surf);
  std::vector<Vec<D>>& f_points = out.force[points_];
  std::vector<AxialVec<D>>& t_points = out.torque[points_];
  std::vector<Vec<D>>& f_nodes = out.force[other_];
  // Scatter in particle order: the same sums for any thread count.
  for (std::size_t q = 0; q < touched.size(); ++q) {
    const Hit& h = touched[q];
    const Index i = h.particle;
    const Push& f = push[q];
    ++last_.active;
    last_.max_overlap_m = std::max(last_.max_overlap_m, h.overlap);
    last_.normal_force_n += f.normal;
    last_.force_on_other -= f.force;
    f_points[at(i)] += f.force;
    // The arm -r n from the centre to the contact point; only the tangential part of the
    // force has a moment about the centre.
    if (!t_points.empty())
      t_points[at(i)] += moment_of<D>(Vec<D>(-(*pts->radius)[at(i)] * h.n), f.force);
    const auto& face = faces[at(h.face)];
    for (int k = 0; k < kF; ++k)
      f_nodes[at(face[at(k)])] -= h.where.weight[at(k)] * f.force;
    add_load(*surf, h);
  }
}

template class ParticleSurface<2>;
template class ParticleSurface<3>;

}  // namespace crater::contact
