// What the pairings share; see pairing.hpp.
#include "contact/pairing.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>

#include "contact/penalty.hpp"
#include "parallel/parallel.hpp"
#include "parallel/reproducible_sum.hpp"

namespace crater::contact {

template <int D>
Pairing<D>::Pairing(const ContactSettings& settings, std::size_t points, std::size_t other,
                    const PartList<D>& parts)
    : settings_(settings),
      points_(points),
      other_(other),
      name_(parts[points]->name() + "-" + parts[other]->name()) {
  for (std::size_t k = 0; k < 2; ++k) {
    const std::string& group = settings.surface_group[k];
    if (group.empty()) continue;
    const std::size_t part = settings.parts[k];
    const auto* nodes = parts[part]->group_nodes(group);
    const auto surface = parts[part]->contact_surface();
    if (!nodes || !surface)  // the scenario reader checks both
      throw std::logic_error("contact '" + name_ + "': part '" + parts[part]->name() +
                             "' has no surface group '" + group + "'");
    filter_[part == points ? 0 : 1] = SurfaceFilter<D>(*nodes, surface->node_position->size());
  }
}

template <int D>
void Pairing<D>::restart(std::size_t n_points, std::size_t n_other) {
  last_.clear();
  load_.points.reset(n_points);
  load_.other.reset(n_other);
}

template <int D>
void Pairing<D>::limit_sides(PairLimits& limits, Real k_max, Real m_points, Real m_other) const {
  auto offer = [&](StepSearch& side, Real m, const char* what) {
    if (!(m > 0) || !(m < std::numeric_limits<Real>::infinity())) return;
    side.consider(spring_step(k_max, m, settings_.damping_ratio), -1, [&] {
      return fmt::format("contact '{}': penalty spring of stiffness {:.3g} N/m on its lightest {}",
                         name_, k_max, what);
    });
  };
  offer(limits.points, m_points, "body");
  offer(limits.other, m_other, "body of the other side");
}

template <int D>
void Pairing<D>::limit_by_summed_springs(StepSearch& search, const BodyLoads& load,
                                         const std::vector<Real>& mass, const char* what,
                                         const std::vector<std::int64_t>* id) const {
  // Bodies are named by id (a particle's index moves at each re-sort; a node's is its id), and
  // on equal steps the smallest id wins (StepSearch), whatever order the bodies come in. The
  // step falls as k/m grows (spring_step is a function of sqrt(k/m) alone), so the search
  // takes the largest ratio first, then the step of the bodies whose ratio is close enough
  // to it that their steps may round to the same value; only the winner's reason is written.
  auto usable = [&](Index i) { return at(i) < mass.size() && load[at(i)] > 0 && mass[at(i)] > 0; };
  Real q_max = 0;
  for (const Index i : load.bodies())
    if (usable(i)) q_max = std::max(q_max, load[at(i)] / mass[at(i)]);
  if (!(q_max > 0)) return;
  // A ratio 1e-9 below the largest gives a step 5e-10 longer, far more than a rounding.
  const Real q_near = q_max * (1 - Real(1e-9));
  Real best = std::numeric_limits<Real>::infinity();
  Index best_body = -1, best_i = -1;
  for (const Index i : load.bodies()) {
    if (!usable(i) || !(load[at(i)] / mass[at(i)] >= q_near)) continue;
    const Real dt = spring_step(load[at(i)], mass[at(i)], settings_.damping_ratio);
    const Index body = id && at(i) < id->size() ? (*id)[at(i)] : i;
    if (dt < best || (dt == best && body < best_body)) {
      best = dt;
      best_body = body;
      best_i = i;
    }
  }
  if (best_i < 0) return;
  search.consider(best, best_body, [&] {
    return fmt::format("contact '{}': {} {} held by penalty springs summing to {:.3g} N/m", name_,
                       what, best_body, load[at(best_i)]);
  });
}

template <int D>
void Pairing<D>::add_diagnostics(std::vector<parts::Diagnostic>& d) const {
  d.push_back({"contact_" + name_ + "_pairs", static_cast<Real>(last_.active)});
  d.push_back({"contact_" + name_ + "_max_overlap_m", last_.max_overlap_m});
  d.push_back({"contact_" + name_ + "_normal_force_n", last_.normal_force_n});
}

template <int D>
void Pairing<D>::add_history_columns(std::vector<std::string>& cols) const {
  for (int k = 0; k < D; ++k)
    cols.push_back(fmt::format("force_{}_{}", name_, "xyz"[k]));
}

template <int D>
void Pairing<D>::add_history_values(std::vector<Real>& v) const {
  for (int k = 0; k < D; ++k)
    v.push_back(last_.force_on_other[k]);
}

template <int D>
std::vector<Real> sums_head(const std::vector<ContactSums<D>*>& sums) {
  constexpr std::size_t kT = D + 1, kHead = kT + 2;
  std::vector<Real> head(sums.size() * kHead, 0);
  for (std::size_t c = 0; c < sums.size(); ++c) {
    Real* h = &head[c * kHead];
    h[0] = static_cast<Real>(sums[c]->active);
    h[1] = sums[c]->max_overlap_m;
    for (const auto& t : sums[c]->terms)
      for (std::size_t q = 0; q < kT; ++q)
        if (std::isfinite(t[q])) h[2 + q] = std::max(h[2 + q], std::abs(t[q]));
  }
  return head;
}

template <int D>
void finish_sums(const std::vector<ContactSums<D>*>& sums, const parallel::Comm* comm,
                 const std::vector<Real>* heads) {
  // The heads over the ranks (counts: exact sums; the rest: maxima), then each term's sum from
  // its levels.
  constexpr std::size_t kT = D + 1, kHead = kT + 2;
  const bool ranks = comm && comm->size() > 1 && !sums.empty();
  // One rank: its own head; on ranks, the heads every rank gathered (this rank's among them).
  std::vector<Real> head = ranks ? std::vector<Real>(sums.size() * kHead, 0) : sums_head(sums);
  if (ranks) {
    if (!heads || heads->size() != head.size() * at(comm->size()))
      throw std::logic_error("contact sums: every rank's head expected");
    for (std::size_t r = 0; r * head.size() < heads->size(); ++r)
      for (std::size_t c = 0; c < sums.size(); ++c) {
        const Real* g = &(*heads)[r * head.size() + c * kHead];
        Real* h = &head[c * kHead];
        h[0] += g[0];
        for (std::size_t q = 1; q < kHead; ++q)
          h[q] = std::max(h[q], g[q]);
      }
  }
  constexpr std::size_t kWords = parallel::ReproducibleSum::kLevels + 1;
  std::vector<parallel::ReproducibleSum> total;
  std::vector<Real> partials(sums.size() * kT * kWords);
  for (std::size_t c = 0; c < sums.size(); ++c) {
    const Real* h = &head[c * kHead];
    const auto count = static_cast<std::int64_t>(h[0]);
    for (std::size_t q = 0; q < kT; ++q) {
      parallel::ReproducibleSum s(h[2 + q], count);
      for (const auto& t : sums[c]->terms)
        s.add(t[q]);
      const auto p = s.partials();
      std::copy(p.begin(), p.end(),
                partials.begin() + static_cast<std::ptrdiff_t>((c * kT + q) * kWords));
      total.push_back(s);
    }
  }
  if (ranks) comm->sum_exact(std::span<Real>(partials));
  for (std::size_t c = 0; c < sums.size(); ++c) {
    ContactSums<D>& s = *sums[c];
    s.active = static_cast<Index>(head[c * kHead]);
    s.max_overlap_m = head[c * kHead + 1];
    std::array<Real, kT> value{};
    for (std::size_t q = 0; q < kT; ++q) {
      parallel::ReproducibleSum& t = total[c * kT + q];
      parallel::ReproducibleSum::Partials p{};
      std::copy_n(partials.begin() + static_cast<std::ptrdiff_t>((c * kT + q) * kWords), kWords,
                  p.begin());
      t.set_partials(p);
      value[q] = t.value();
    }
    s.normal_force_n = value[0];
    for (int k = 0; k < D; ++k)
      s.force_on_other[k] = value[static_cast<std::size_t>(k + 1)];
  }
}

template <int D>
Real lightest_face_node(const parts::ContactSurface<D>& surf) {
  Real m = std::numeric_limits<Real>::infinity();
  for (const auto& face : *surf.faces)
    for (Index n : face)
      if ((*surf.node_mass)[at(n)] > 0) m = std::min(m, (*surf.node_mass)[at(n)]);
  return m;
}

template <int D>
Real lightest_particle(const parts::ContactPoints<D>& pts) {
  if (pts.whole_count >= 0) return pts.whole_lightest_kg;    // a contact zone's view
  if (!std::isnan(pts.lightest_kg)) return pts.lightest_kg;  // kept by the part
  return parallel::min_over(static_cast<Index>(pts.mass->size()),
                            std::numeric_limits<Real>::infinity(),
                            [&](Index i) { return (*pts.mass)[at(i)]; });
}

template class Pairing<2>;
template class Pairing<3>;
template std::vector<Real> sums_head<2>(const std::vector<ContactSums<2>*>&);
template std::vector<Real> sums_head<3>(const std::vector<ContactSums<3>*>&);
template void finish_sums<2>(const std::vector<ContactSums<2>*>&, const parallel::Comm*,
                             const std::vector<Real>*);
template void finish_sums<3>(const std::vector<ContactSums<3>*>&, const parallel::Comm*,
                             const std::vector<Real>*);
template Real lightest_face_node<2>(const parts::ContactSurface<2>&);
template Real lightest_face_node<3>(const parts::ContactSurface<3>&);
template Real lightest_particle<2>(const parts::ContactPoints<2>&);
template Real lightest_particle<3>(const parts::ContactPoints<3>&);

}  // namespace crater::contact
