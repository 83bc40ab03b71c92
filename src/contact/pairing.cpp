// What the pairings share; see pairing.hpp.
#include "contact/pairing.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <stdexcept>

#include "contact/penalty.hpp"
#include "parallel/parallel.hpp"

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
  last_ = ContactSums<D>{};
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
  // on equal steps the smallest id wins (StepSearch).
  for (Index i : load.loaded()) {
    if (at(i) >= mass.size() || !(load[at(i)] > 0) || !(mass[at(i)] > 0)) continue;
    const Index body = id && at(i) < id->size() ? (*id)[at(i)] : i;
    search.consider(spring_step(load[at(i)], mass[at(i)], settings_.damping_ratio), body, [&] {
      return fmt::format("contact '{}': {} {} held by penalty springs summing to {:.3g} N/m", name_,
                         what, body, load[at(i)]);
    });
  }
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
Real lightest_face_node(const parts::ContactSurface<D>& surf) {
  Real m = std::numeric_limits<Real>::infinity();
  for (const auto& face : *surf.faces)
    for (Index n : face)
      if ((*surf.node_mass)[at(n)] > 0) m = std::min(m, (*surf.node_mass)[at(n)]);
  return m;
}

template <int D>
Real lightest_particle(const parts::ContactPoints<D>& pts) {
  if (pts.whole_count >= 0) return pts.whole_lightest_kg;  // a contact zone's view
  return parallel::min_over(static_cast<Index>(pts.mass->size()),
                            std::numeric_limits<Real>::infinity(),
                            [&](Index i) { return (*pts.mass)[at(i)]; });
}

template class Pairing<2>;
template class Pairing<3>;
template Real lightest_face_node<2>(const parts::ContactSurface<2>&);
template Real lightest_face_node<3>(const parts::ContactSurface<3>&);
template Real lightest_particle<2>(const parts::ContactPoints<2>&);
template Real lightest_particle<3>(const parts::ContactPoints<3>&);

}  // namespace crater::contact
