// SPH particles against DEM grains; see particle_particle.hpp and coupling.hpp.
#include "contact/particle_particle.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <limits>
#include <span>

#include "contact/face_search.hpp"
#include "contact/penalty.hpp"
#include "core/axial_vec.hpp"
#include "neighbors/neighbor_list.hpp"
#include "parallel/parallel.hpp"

namespace crater::contact {

template <int D>
void ParticleParticle<D>::limit_step(const PartList<D>& parts, PairLimits& limits) const {
  const auto pts = parts[this->points_]->contact_points();
  if (!pts || parts::whole_point_count(*pts) == 0) return;
  const Real m_min = lightest_particle(*pts);
  const auto grains = parts[this->other_]->contact_points();
  if (!grains || parts::whole_point_count(*grains) == 0) return;
  const Real r_max = largest_radius(*grains);
  const Real k_max = this->settings_.penalty_scale * grain_modulus_pa_ * (D == 3 ? r_max : Real(1));
  const Real m_grain = lightest_particle(*grains);
  limits.pair.consider(spring_step(k_max, std::min(m_min, m_grain), this->settings_.damping_ratio),
                       -1, [&] {
                         return fmt::format("contact '{}': penalty spring of stiffness {:.3g} N/m",
                                            this->name_, k_max);
                       });
  this->limit_sides(limits, k_max, m_min, m_grain);
  // Bodies pressed by several springs at once (found afresh when particles were removed
  // since the last apply(): the cached sums are per particle index).
  if (this->load_stale(pts->mass->size(), grains->mass->size())) measure_load(parts);
  this->limit_by_summed_springs(limits.points, this->load_.points, *pts->mass, "particle", pts->id);
  this->limit_by_summed_springs(limits.other, this->load_.other, *grains->mass,
                                "particle of the other part", grains->id);
}

template <int D>
std::vector<typename ParticleParticle<D>::Pair> ParticleParticle<D>::pairs(
    const parts::ContactPoints<D>& a, const parts::ContactPoints<D>& b, CrossCandidates<D>* kept) {
  const Index na = static_cast<Index>(a.position->size());
  const Index nb = static_cast<Index>(b.position->size());
  if (na == 0 || nb == 0) return {};
  const Real ra_max = largest_radius(a);
  const Real rb_max = largest_radius(b);
  const std::span<const Vec<D>> xa(*a.position);
  const std::span<const Vec<D>> xb(*b.position);
  neighbors::NeighborList fresh;
  if (!kept) neighbors::build_cross_list<D>(xa, xb, ra_max + rb_max, fresh);
  // On ranks, a contact zone's view (b's, marked by its own particles) holds other particles
  // from step to step, and a kept list keeps its rows by id (candidates.hpp): there the rows
  // are b's, and the pairs are put back in a's order below.
  const bool by_b = kept && b.own && !a.own;
  // A kept list's extra candidates do not overlap: the pairs are those of a fresh list.
  const neighbors::NeighborList& list =
      !kept  ? fresh
      : by_b ? kept->find(xb, numbering(b), xa, numbering(a), ra_max + rb_max)
             : kept->find(xa, numbering(a), xb, numbering(b), ra_max + rb_max);
  std::vector<Pair> all(list.indices.size());
  parallel::for_each(
      by_b ? nb : na,
      [&](Index row_of) {
        const auto row = list.of(row_of);
        const auto base = at(list.offsets[at(row_of)]);
        for (std::size_t q = 0; q < row.size(); ++q) {
          const Index i = by_b ? row[q] : row_of, j = by_b ? row_of : row[q];
          const Vec<D> d = (*a.position)[at(i)] - (*b.position)[at(j)];
          const Real dist = d.norm();
          const Real overlap = (*a.radius)[at(i)] + (*b.radius)[at(j)] - dist;
          if (overlap <= 0 || !(dist > 0)) continue;
          all[base + q] = {i, j, overlap, dist, d};
        }
      },
      parallel::Cost::heavy);
  const std::vector<Index> touching =
      parallel::select(static_cast<Index>(all.size()), [&](Index q) { return all[at(q)].a >= 0; });
  std::vector<Pair> found(touching.size());
  parallel::for_each(static_cast<Index>(touching.size()),
                     [&](Index q) { found[at(q)] = all[at(touching[at(q)])]; });
  if (by_b)
    std::sort(found.begin(), found.end(),
              [](const Pair& x, const Pair& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
  return found;
}

template <int D>
Real ParticleParticle<D>::stiffness(const parts::ContactPoints<D>& grains, Index j) const {
  return this->settings_.penalty_scale * grain_modulus_pa_ *
         (D == 3 ? (*grains.radius)[at(j)] : Real(1));
}

template <int D>
void ParticleParticle<D>::add_load(const parts::ContactPoints<D>& grains, const Pair& pp) const {
  const Real k = stiffness(grains, pp.b);
  this->load_.points.add(pp.a, k);
  this->load_.other.add(pp.b, k);
}

template <int D>
void ParticleParticle<D>::measure_load(const PartList<D>& parts) const {
  const auto pts = parts[this->points_]->contact_points();
  const auto grains = parts[this->other_]->contact_points();
  this->measure(pts->position->size(), grains->position->size(), pairs(*pts, *grains, &kept_),
                [&](const Pair& pp) { add_load(*grains, pp); });
}

template <int D>
void ParticleParticle<D>::apply(const PartList<D>& parts, Real /*dt_s*/, ContactForces<D>& out) {
  const auto pa = parts[this->points_]->contact_points();
  const auto pb = parts[this->other_]->contact_points();
  const parts::ContactPoints<D>& a = *pa;
  const parts::ContactPoints<D>& b = *pb;
  this->restart(a.position->size(), b.position->size());
  this->load_.known = true;
  const std::vector<Pair> found = pairs(a, b, &kept_);
  // Per pair results, in list order (a ascending, then b ascending).
  struct PairForce {
    Vec<D> force = Vec<D>::Zero();  // on a
    Vec<D> arm_b = Vec<D>::Zero();  // from b's centre to the contact point
    Real normal = 0;
  };
  std::vector<PairForce> push(found.size());
  parallel::for_each(static_cast<Index>(found.size()), [&](Index q) {
    const Pair& pp = found[at(q)];
    PairForce& pf = push[at(q)];
    const Vec<D> n = pp.d / pp.dist;  // from b to a
    pf.arm_b = (*b.radius)[at(pp.b)] * n;
    Vec<D> v = (*a.velocity)[at(pp.a)] - (*b.velocity)[at(pp.b)];
    if (b.angular_velocity) v -= spin_cross<D>((*b.angular_velocity)[at(pp.b)], pf.arm_b);
    pf.force = penalty_force<D>(stiffness(b, pp.b), pp.overlap, n, v,
                                reduced_mass((*a.mass)[at(pp.a)], (*b.mass)[at(pp.b)]),
                                this->settings_.damping_ratio, this->settings_.friction, pf.normal);
  });
  std::vector<Vec<D>>& f_a = out.force[this->points_];
  std::vector<Vec<D>>& f_b = out.force[this->other_];
  std::vector<AxialVec<D>>& t_b = out.torque[this->other_];
  for (std::size_t q = 0; q < found.size(); ++q) {
    const Pair& pp = found[q];
    const PairForce& pf = push[q];
    // On ranks, the pair counts where its first side's particle is owned (its second's, when
    // only that side's view marks its own).
    if (a.own ? parts::counts_here(a, pp.a) : parts::counts_here(b, pp.b))
      this->last_.add(pp.overlap, pf.normal, -pf.force);
    f_a[at(pp.a)] += pf.force;
    f_b[at(pp.b)] -= pf.force;
    out.touch(this->points_, pp.a);
    out.touch(this->other_, pp.b);
    if (!t_b.empty()) t_b[at(pp.b)] += moment_of<D>(pf.arm_b, Vec<D>(-pf.force));
    add_load(b, pp);
  }
}

template class ParticleParticle<2>;
template class ParticleParticle<3>;

}  // namespace crater::contact
