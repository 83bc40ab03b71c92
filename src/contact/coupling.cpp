// Contacts between parts; see coupling.hpp.
#include "contact/coupling.hpp"

#include <algorithm>

#include "contact/registry.hpp"
#include "core/axial_vec.hpp"

namespace crater::contact {

template <int D>
Coupling<D>::Coupling(const std::vector<ContactSettings>& contacts, const PartList<D>& parts) {
  for (const ContactSettings& c : contacts) {
    pairings_.push_back(make_pairing<D>(c, parts));
    for (std::size_t k : {pairings_.back()->points(), pairings_.back()->other()})
      if (std::find(involved_.begin(), involved_.end(), k) == involved_.end())
        involved_.push_back(k);
  }
  std::sort(involved_.begin(), involved_.end());
}

template <int D>
parts::StableStep Coupling<D>::stable_step(const PartList<D>& parts) const {
  StepSearch search;
  for (const auto& p : pairings_)
    p->limit_step(parts, search);
  search.best.absolute = true;  // omega dt <= 1/2 is an accuracy bound (penalty.hpp)
  return search.best;
}

template <int D>
void Coupling<D>::apply(const PartList<D>& parts, Real dt_s) {
  if (pairings_.empty()) return;
  // Forces per part in any contact: per particle, or per node of a surface.
  ContactForces<D> out;
  out.force.resize(parts.size());
  out.torque.resize(parts.size());
  for (std::size_t k : involved_) {
    Index n = 0;
    if (const auto pts = parts[k]->contact_points())
      n = static_cast<Index>(pts->position->size());
    else if (const auto surf = parts[k]->contact_surface())
      n = static_cast<Index>(surf->node_position->size());
    out.force[k].assign(at(n), Vec<D>::Zero());
    if (const auto pts = parts[k]->contact_points(); pts && pts->angular_velocity)
      out.torque[k].assign(at(n), axial_zero<D>());
  }
  for (auto& p : pairings_)
    p->apply(parts, dt_s, out);
  for (std::size_t k : involved_)
    parts[k]->add_contact_forces(out.force[k], out.torque[k]);
}

template <int D>
std::vector<parts::Diagnostic> Coupling<D>::diagnostics() const {
  std::vector<parts::Diagnostic> d;
  for (const auto& p : pairings_)
    p->add_diagnostics(d);
  return d;
}

template <int D>
std::vector<std::string> Coupling<D>::history_columns() const {
  std::vector<std::string> cols;
  for (const auto& p : pairings_)
    p->add_history_columns(cols);
  return cols;
}

template <int D>
std::vector<Real> Coupling<D>::history_values() const {
  std::vector<Real> v;
  for (const auto& p : pairings_)
    p->add_history_values(v);
  return v;
}

template class Coupling<2>;
template class Coupling<3>;

}  // namespace crater::contact
