// Particles against a solid's surface; see particle_surface.hpp and coupling.hpp.
#include "contact/particle_surface.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>

#include "contact/face_search.hpp"
#include "contact/penalty.hpp"
#include "core/axial_vec.hpp"
#include "neighbors/neighbor_list.hpp"
#include "parallel/parallel.hpp"

namespace crater::contact {

namespace {

// The penalty stiffness of a face [N/m].
template <int D>
Real face_stiffness(const ContactSettings& settings, const parts::ContactSurface<D>& surf,
                    Index face) {
  return settings.penalty_scale * (*surf.face_stiffness)[at(face)];
}

// The force of one hit and its normal part.
template <int D>
struct Push {
  Vec<D> force = Vec<D>::Zero();  // on the particle
  Real normal = 0;
};

// The force of each hit (in parallel); keeps the particles' offsets.
template <int D>
std::vector<Push<D>> pushes(const ContactSettings& settings, const std::vector<FaceHit<D>>& hits,
                            Real dt, const parts::ContactPoints<D>& pts,
                            const parts::ContactSurface<D>& surf) {
  constexpr int kF = parts::kFaceNodes<D>;
  const auto& faces = *surf.faces;
  const Index np = static_cast<Index>(pts.position->size());
  const bool offsets = pts.surface_offset && pts.surface_overlap;
  if (offsets) {
    // A particle touching no face has no offset (it starts afresh at its next touch).
    std::vector<char> touching(at(np), 0);
    for (const FaceHit<D>& h : hits)
      touching[at(h.body)] = 1;
    parallel::for_each(np, [&](Index i) {
      if (!touching[at(i)]) (*pts.surface_offset)[at(i)] = -1;
    });
  }
  std::vector<Push<D>> push(hits.size());
  parallel::for_each(static_cast<Index>(hits.size()), [&](Index q) {
    const FaceHit<D>& h = hits[at(q)];
    const Index i = h.body;
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
    Push<D>& out = push[at(q)];
    out.force = penalty_force<D>(face_stiffness(settings, surf, h.face), pushed, h.n, v - v_face,
                                 reduced_mass((*pts.mass)[at(i)], m_face), settings.damping_ratio,
                                 settings.friction, out.normal);
  });
  return push;
}

}  // namespace

template <int D>
void ParticleSurface<D>::limit_step(const PartList<D>& parts, PairLimits& limits) const {
  const auto pts = parts[this->points_]->contact_points();
  if (!pts || parts::whole_point_count(*pts) == 0) return;
  const Real m_min = lightest_particle(*pts);
  const auto surf = this->surface_of(parts, 1);
  if (!surf || surf->face_stiffness->empty()) return;
  const Real k_max = this->settings_.penalty_scale *
                     *std::max_element(surf->face_stiffness->begin(), surf->face_stiffness->end());
  // The spring joins the particle to a face node, which may be the lighter of the two.
  const Real node_min = lightest_face_node(*surf);
  limits.pair.consider(
      spring_step(k_max, reduced_mass(m_min, node_min), this->settings_.damping_ratio), -1, [&] {
        return fmt::format("contact '{}': penalty spring of stiffness {:.3g} N/m", this->name_,
                           k_max);
      });
  this->limit_sides(limits, k_max, m_min, node_min);
  // Bodies pressed by several springs at once (found afresh when particles were removed
  // since the last apply(): the cached sums are per particle index).
  if (this->load_stale(pts->mass->size(), surf->node_mass->size())) measure_load(parts);
  this->limit_by_summed_springs(limits.points, this->load_.points, *pts->mass, "particle", pts->id);
  this->limit_by_summed_springs(limits.other, this->load_.other, *surf->node_mass, "surface node");
}

template <int D>
void ParticleSurface<D>::add_load(const parts::ContactSurface<D>& surf, const Hit& h) const {
  const Real k = face_stiffness(this->settings_, surf, h.face);
  this->load_.points.add(h.body, k);
  const auto& face = (*surf.faces)[at(h.face)];
  for (int q = 0; q < parts::kFaceNodes<D>; ++q)
    this->load_.other.add(face[at(q)], k * h.where.weight[at(q)]);
}

template <int D>
void ParticleSurface<D>::measure_load(const PartList<D>& parts) const {
  const auto pts = parts[this->points_]->contact_points();
  const auto surf = this->surface_of(parts, 1);
  this->measure(pts->position->size(), surf->node_position->size(),
                particle_face_hits(*pts, *surf, kept_), [&](const Hit& h) { add_load(*surf, h); });
}

template <int D>
void ParticleSurface<D>::apply(const PartList<D>& parts, Real dt_s, ContactForces<D>& out) {
  constexpr int kF = parts::kFaceNodes<D>;
  const auto pts = parts[this->points_]->contact_points();
  const auto surf = this->surface_of(parts, 1);
  const auto& faces = *surf->faces;
  const Index np = static_cast<Index>(pts->position->size());
  this->restart(at(np), surf->node_position->size());
  this->load_.known = true;
  if (faces.empty() || np == 0) return;

  const std::vector<Hit> touched = particle_face_hits(*pts, *surf, kept_);
  const std::vector<Push<D>> push = pushes(this->settings_, touched, dt_s, *pts, *surf);
  std::vector<Vec<D>>& f_points = out.force[this->points_];
  std::vector<AxialVec<D>>& t_points = out.torque[this->points_];
  std::vector<Vec<D>>& f_nodes = out.force[this->other_];
  // Scatter in particle order: the same sums for any thread count.
  for (std::size_t q = 0; q < touched.size(); ++q) {
    const Hit& h = touched[q];
    const Index i = h.body;
    const Push<D>& f = push[q];
    if (parts::counts_here(*pts, i)) this->last_.add(h.overlap, f.normal, -f.force);
    f_points[at(i)] += f.force;
    out.touch(this->points_, i);
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
