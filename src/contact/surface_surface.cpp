// The surfaces of two solids; see surface_surface.hpp and coupling.hpp.
#include "contact/surface_surface.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <span>

#include "contact/penalty.hpp"
#include "neighbors/neighbor_list.hpp"
#include "parallel/parallel.hpp"

namespace crater::contact {

template <int D>
void SurfaceSurface<D>::limit_step(const PartList<D>& parts, StepSearch& search) const {
  const auto sa = parts[points_]->contact_surface();
  const auto sb = parts[other_]->contact_surface();
  if (!sa || !sb || sa->face_stiffness->empty() || sb->face_stiffness->empty()) return;
  const Real k_max =
      settings_.penalty_scale *
      std::min(*std::max_element(sa->face_stiffness->begin(), sa->face_stiffness->end()),
               *std::max_element(sb->face_stiffness->begin(), sb->face_stiffness->end()));
  search.consider(spring_step(k_max, reduced_mass(lightest_face_node(*sa), lightest_face_node(*sb)),
                              settings_.damping_ratio),
                  -1, [&] {
                    return fmt::format("contact '{}': penalty spring of stiffness {:.3g} N/m",
                                       name_, k_max);
                  });
  if (!load_.known || load_.points.size() != sa->node_mass->size() ||
      load_.other.size() != sb->node_mass->size())
    measure_load(parts);
  for (int side = 0; side < 2; ++side) {
    const std::vector<Real>& load = side == 0 ? load_.points : load_.other;
    const std::vector<Real>& mass = side == 0 ? *sa->node_mass : *sb->node_mass;
    for (std::size_t i = 0; i < load.size() && i < mass.size(); ++i) {
      if (!(load[i] > 0) || !(mass[i] > 0)) continue;
      search.consider(spring_step(load[i], mass[i], settings_.damping_ratio), static_cast<Index>(i),
                      [&] {
                        return fmt::format(
                            "contact '{}': node {} of '{}' held by penalty springs summing to "
                            "{:.3g} N/m",
                            name_, i, parts[side == 0 ? points_ : other_]->name(), load[i]);
                      });
    }
  }
}

template <int D>
std::vector<typename SurfaceSurface<D>::NodeHit> SurfaceSurface<D>::node_hits(
    const parts::ContactSurface<D>& nodes_of, const parts::ContactSurface<D>& faces_of) {
  constexpr int kF = parts::kFaceNodes<D>;
  const auto& xa = *nodes_of.node_position;
  const auto& xb = *faces_of.node_position;
  const auto& faces = *faces_of.faces;
  // The surface nodes of `nodes_of` that carry mass, ascending, with the stiffest of their
  // own faces.
  std::vector<Real> node_k(xa.size(), 0);
  for (std::size_t f = 0; f < nodes_of.faces->size(); ++f)
    for (Index n : (*nodes_of.faces)[f])
      node_k[at(n)] = std::max(node_k[at(n)], (*nodes_of.face_stiffness)[f]);
  std::vector<Index> nodes;
  for (std::size_t n = 0; n < xa.size(); ++n)
    if (node_k[n] > 0 && (*nodes_of.node_mass)[n] > 0) nodes.push_back(static_cast<Index>(n));
  std::vector<NodeHit> hits(nodes.size());
  const Index nf = static_cast<Index>(faces.size());
  if (nf == 0 || nodes.empty()) return hits;

  std::vector<Vec<D>> centre(at(nf));
  std::vector<Real> size(at(nf));
  Real half_size = 0;
  for (Index f = 0; f < nf; ++f) {
    std::array<Vec<D>, kF> fx;
    Vec<D> c = Vec<D>::Zero();
    for (int k = 0; k < kF; ++k) {
      fx[at(k)] = xb[at(faces[at(f)][at(k)])];
      c += fx[at(k)] / Real(kF);
    }
    centre[at(f)] = c;
    for (int k = 0; k < kF; ++k)
      half_size = std::max(half_size, (fx[at(k)] - c).norm());
    if constexpr (D == 2) {
      size[at(f)] = (fx[1] - fx[0]).norm();
    } else {
      size[at(f)] = std::sqrt(Real(0.5) * (fx[2] - fx[0]).cross(fx[3] - fx[1]).norm());
    }
  }
  std::vector<Vec<D>> x(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i)
    x[i] = xa[at(nodes[i])];
  // A node within half a face's size behind it, projecting onto it, is within
  // sqrt(half_size^2 + (half_size)^2) of its centre.
  neighbors::NeighborList candidates;
  neighbors::build_cross_list<D>(std::span<const Vec<D>>(x), std::span<const Vec<D>>(centre),
                                 Real(1.5) * half_size, candidates);
  parallel::for_each(static_cast<Index>(nodes.size()), [&](Index i) {
    NodeHit best;
    best.node = nodes[at(i)];
    const Vec<D>& p = x[at(i)];
    for (Index f : candidates.of(i)) {
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
      if (best.face >= 0 && (-s > best.overlap || (-s == best.overlap && f > best.face))) continue;
      best.face = f;
      best.where = fp;
      best.n = nf_out;
      best.overlap = -s;
      best.k = std::min((*faces_of.face_stiffness)[at(f)], node_k[at(best.node)]);
    }
    hits[at(i)] = best;
  });
  return hits;
}

template <int D>
ContactSums<D> SurfaceSurface<D>::node_surface(const Side& a, const Side& b,
                                               const std::vector<NodeHit>& hits, Real sign) const {
  constexpr int kF = parts::kFaceNodes<D>;
  const auto& faces = *b.surface.faces;
  ContactSums<D> sums;
  std::vector<Vec<D>> push(hits.size(), Vec<D>::Zero());
  std::vector<Real> normal(hits.size(), 0);
  if (a.force)
    parallel::for_each(static_cast<Index>(hits.size()), [&](Index q) {
      const NodeHit& h = hits[at(q)];
      if (h.face < 0) return;
      const auto& face = faces[at(h.face)];
      Real m_face = 0;
      Vec<D> v_face = Vec<D>::Zero();
      for (int k = 0; k < kF; ++k) {
        m_face += h.where.weight[at(k)] * (*b.surface.node_mass)[at(face[at(k)])];
        v_face += h.where.weight[at(k)] * (*b.surface.node_velocity)[at(face[at(k)])];
      }
      const Vec<D> v = (*a.surface.node_velocity)[at(h.node)] - v_face;
      push[at(q)] = penalty_force<D>(settings_.penalty_scale * h.k, h.overlap, h.n, v,
                                     reduced_mass((*a.surface.node_mass)[at(h.node)], m_face),
                                     settings_.damping_ratio, settings_.friction, normal[at(q)]);
    });
  // Scatter in node order: the same sums for any thread count.
  for (std::size_t q = 0; q < hits.size(); ++q) {
    const NodeHit& h = hits[q];
    if (h.face < 0) continue;
    const auto& face = faces[at(h.face)];
    const Real k = settings_.penalty_scale * h.k;
    a.load[at(h.node)] += k;
    for (int j = 0; j < kF; ++j)
      b.load[at(face[at(j)])] += k * h.where.weight[at(j)];
    if (!a.force) continue;
    ++sums.active;
    sums.max_overlap_m = std::max(sums.max_overlap_m, h.overlap);
    sums.normal_force_n += normal[q];
    sums.force_on_other += sign * push[q];
    (*a.force)[at(h.node)] += push[q];
    for (int j = 0; j < kF; ++j)
      (*b.force)[at(face[at(j)])] -= h.where.weight[at(j)] * push[q];
  }
  return sums;
}

template <int D>
void SurfaceSurface<D>::measure_load(const PartList<D>& parts) const {
  const auto sa = parts[points_]->contact_surface();
  const auto sb = parts[other_]->contact_surface();
  load_.points.assign(sa->node_position->size(), 0);
  load_.other.assign(sb->node_position->size(), 0);
  const Side a{*sa, load_.points, nullptr}, b{*sb, load_.other, nullptr};
  node_surface(a, b, node_hits(*sa, *sb), -1);
  node_surface(b, a, node_hits(*sb, *sa), 1);
  load_.known = true;
}

template <int D>
void SurfaceSurface<D>::apply(const PartList<D>& parts, Real /*dt_s*/, ContactForces<D>& out) {
  const auto sa = parts[points_]->contact_surface();
  const auto sb = parts[other_]->contact_surface();
  this->restart(sa->node_position->size(), sb->node_position->size());
  const Side a{*sa, load_.points, &out.force[points_]}, b{*sb, load_.other, &out.force[other_]};
  for (const ContactSums<D>& sums :
       {node_surface(a, b, node_hits(*sa, *sb), -1), node_surface(b, a, node_hits(*sb, *sa), 1)}) {
    last_.active += sums.active;
    last_.max_overlap_m = std::max(last_.max_overlap_m, sums.max_overlap_m);
    last_.normal_force_n += sums.normal_force_n;
    last_.force_on_other += sums.force_on_other;
  }
  load_.known = true;
}

template class SurfaceSurface<2>;
template class SurfaceSurface<3>;

}  // namespace crater::contact
