// The surfaces of two solids; see surface_surface.hpp and coupling.hpp.
#include "contact/surface_surface.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <span>

#include "contact/face_search.hpp"
#include "contact/penalty.hpp"
#include "neighbors/neighbor_list.hpp"
#include "parallel/parallel.hpp"

namespace crater::contact {

namespace {

// One side of a direction: its surface, spring sums and forces (null: sums only).
template <int D>
struct Side {
  const parts::ContactSurface<D>& surface;
  BodyLoads& load;
  std::vector<Vec<D>>* force;  // null: loads only
};

// The spring sums and forces of one direction, the nodes of `a` against the faces of `b`.
// Returns the contact's diagnostics of this direction, force_on_other = sign x the sum of the
// forces on a's nodes.
template <int D>
ContactSums<D> node_surface(const ContactSettings& settings, const Side<D>& a, const Side<D>& b,
                            const std::vector<FaceHit<D>>& hits, Real sign) {
  constexpr int kF = parts::kFaceNodes<D>;
  const auto& faces = *b.surface.faces;
  ContactSums<D> sums;
  std::vector<Vec<D>> push(hits.size(), Vec<D>::Zero());
  std::vector<Real> normal(hits.size(), 0);
  if (a.force)
    parallel::for_each(static_cast<Index>(hits.size()), [&](Index q) {
      const FaceHit<D>& h = hits[at(q)];
      if (h.face < 0) return;
      const auto& face = faces[at(h.face)];
      Real m_face = 0;
      Vec<D> v_face = Vec<D>::Zero();
      for (int k = 0; k < kF; ++k) {
        m_face += h.where.weight[at(k)] * (*b.surface.node_mass)[at(face[at(k)])];
        v_face += h.where.weight[at(k)] * (*b.surface.node_velocity)[at(face[at(k)])];
      }
      const Vec<D> v = (*a.surface.node_velocity)[at(h.body)] - v_face;
      push[at(q)] = penalty_force<D>(settings.penalty_scale * h.k, h.overlap, h.n, v,
                                     reduced_mass((*a.surface.node_mass)[at(h.body)], m_face),
                                     settings.damping_ratio, settings.friction, normal[at(q)]);
    });
  // Scatter in node order: the same sums for any thread count.
  for (std::size_t q = 0; q < hits.size(); ++q) {
    const FaceHit<D>& h = hits[q];
    if (h.face < 0) continue;
    const auto& face = faces[at(h.face)];
    const Real k = settings.penalty_scale * h.k;
    a.load.add(h.body, k);
    for (int j = 0; j < kF; ++j)
      b.load.add(face[at(j)], k * h.where.weight[at(j)]);
    if (!a.force) continue;
    sums.add(h.overlap, normal[q], sign * push[q]);
    (*a.force)[at(h.body)] += push[q];
    for (int j = 0; j < kF; ++j)
      (*b.force)[at(face[at(j)])] -= h.where.weight[at(j)] * push[q];
  }
  return sums;
}

}  // namespace

template <int D>
void SurfaceSurface<D>::limit_step(const PartList<D>& parts, PairLimits& limits) const {
  const auto sa = this->surface_of(parts, 0);
  const auto sb = this->surface_of(parts, 1);
  if (!sa || !sb || sa->face_stiffness->empty() || sb->face_stiffness->empty()) return;
  const Real k_max =
      this->settings_.penalty_scale *
      std::min(*std::max_element(sa->face_stiffness->begin(), sa->face_stiffness->end()),
               *std::max_element(sb->face_stiffness->begin(), sb->face_stiffness->end()));
  const Real ma = lightest_face_node(*sa), mb = lightest_face_node(*sb);
  limits.pair.consider(spring_step(k_max, reduced_mass(ma, mb), this->settings_.damping_ratio), -1,
                       [&] {
                         return fmt::format("contact '{}': penalty spring of stiffness {:.3g} N/m",
                                            this->name_, k_max);
                       });
  this->limit_sides(limits, k_max, ma, mb);
  if (this->load_stale(sa->node_mass->size(), sb->node_mass->size())) measure_load(parts);
  for (int side = 0; side < 2; ++side) {
    const BodyLoads& load = side == 0 ? this->load_.points : this->load_.other;
    const std::vector<Real>& mass = side == 0 ? *sa->node_mass : *sb->node_mass;
    StepSearch& search = side == 0 ? limits.points : limits.other;
    for (const Index node : load.loaded()) {  // ascending: the first node wins ties
      const auto i = at(node);
      if (i >= mass.size() || !(load[i] > 0) || !(mass[i] > 0)) continue;
      search.consider(spring_step(load[i], mass[i], this->settings_.damping_ratio), node, [&] {
        return fmt::format(
            "contact '{}': node {} of '{}' held by penalty springs summing to "
            "{:.3g} N/m",
            this->name_, i, parts[side == 0 ? this->points_ : this->other_]->name(), load[i]);
      });
    }
  }
}

template <int D>
void SurfaceSurface<D>::measure_load(const PartList<D>& parts) const {
  const auto sa = this->surface_of(parts, 0);
  const auto sb = this->surface_of(parts, 1);
  this->load_.points.reset(sa->node_position->size());
  this->load_.other.reset(sb->node_position->size());
  const Side<D> a{*sa, this->load_.points, nullptr}, b{*sb, this->load_.other, nullptr};
  node_surface(this->settings_, a, b, node_face_hits(*sa, *sb), -1);
  node_surface(this->settings_, b, a, node_face_hits(*sb, *sa), 1);
  this->load_.known = true;
}

template <int D>
void SurfaceSurface<D>::apply(const PartList<D>& parts, Real /*dt_s*/, ContactForces<D>& out) {
  const auto sa = this->surface_of(parts, 0);
  const auto sb = this->surface_of(parts, 1);
  this->restart(sa->node_position->size(), sb->node_position->size());
  const Side<D> a{*sa, this->load_.points, &out.force[this->points_]},
      b{*sb, this->load_.other, &out.force[this->other_]};
  for (const ContactSums<D>& sums :
       {node_surface(this->settings_, a, b, node_face_hits(*sa, *sb), -1),
        node_surface(this->settings_, b, a, node_face_hits(*sb, *sa), 1)}) {
    this->last_.append(sums);
  }
  this->load_.known = true;
}

template class SurfaceSurface<2>;
template class SurfaceSurface<3>;

}  // namespace crater::contact
