// Contacts between parts; see coupling.hpp.
#include "contact/coupling.hpp"

#include <algorithm>
#include <stdexcept>

#include "contact/registry.hpp"
#include "contact/spread_coupling.hpp"
#include "core/axial_vec.hpp"
#include "parallel/parallel.hpp"

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
  all_.resize(pairings_.size());
  for (std::size_t c = 0; c < all_.size(); ++c)
    all_[c] = c;
}

template <int D>
Coupling<D>::~Coupling() = default;

template <int D>
void Coupling<D>::spread(const parallel::Comm& comm, const PartList<D>& parts, bool zones) {
  if (comm.size() <= 1 || pairings_.empty()) return;
  std::vector<std::pair<std::size_t, std::size_t>> sides;
  std::vector<std::array<const SurfaceFilter<D>*, 2>> filters;
  for (const auto& p : pairings_) {
    sides.emplace_back(p->points(), p->other());
    filters.push_back({&p->filter(0), &p->filter(1)});
  }
  spread_ = std::make_unique<SpreadContacts<D>>(comm, parts, involved_, std::move(sides),
                                                std::move(filters), zones);
}

template <int D>
std::optional<ViewCounts> Coupling<D>::view_counts() const {
  if (!spread_) return std::nullopt;
  return ViewCounts{spread_->gathers(),        spread_->reused(),
                    spread_->static_kept(),    spread_->zone_views(),
                    spread_->zone_particles(), spread_->zone_whole_particles()};
}

template <int D>
std::vector<std::size_t> Coupling<D>::zoned_parts() const {
  return spread_ ? spread_->zoned() : std::vector<std::size_t>{};
}

template <int D>
parts::StableStep Coupling<D>::stable_step(const PartList<D>& parts) const {
  StepSearch search;
  for (const PairLimits& l : limits(parts))
    for (const StepSearch* s : {&l.pair, &l.points, &l.other})
      search.consider(s->best.dt_s, s->best.entity_id, [&] { return s->best.reason; });
  search.best.absolute = true;  // omega dt <= 1/2 is an accuracy bound (penalty.hpp)
  return search.best;
}

template <int D>
std::vector<PairLimits> Coupling<D>::limits(const PartList<D>& parts) const {
  std::vector<PairLimits> out(pairings_.size());
  // On ranks, whole views of the current state: the parts may have lost particles since the
  // last evaluation (outflow), and one rank's limits see them without; those of the last
  // evaluation when nothing the limits read has changed since (SpreadContacts::for_limits).
  const PartList<D>& on = spread_ ? spread_->for_limits(parts) : parts;
  if (spread_ && spread_->owner_computed() && limits_at_ == spread_->gathers()) return limits_;
  for (std::size_t c = 0; c < pairings_.size(); ++c)
    pairings_[c]->limit_step(on, out[c]);
  // Views that differ from rank to rank (owner-computed): each rank's limits are those of its
  // own bodies' springs, whole; the smallest over the ranks is one rank's.
  if (spread_ && spread_->owner_computed()) spread_->agree(out);
  return out;
}

template <int D>
void Coupling<D>::size_for(const PartList<D>& parts, std::size_t k, ContactForces<D>& out,
                           bool track) const {
  // One view of the part (an SPH part's view computes its particles' contact radii).
  Index n = 0;
  const auto pts = parts[k]->contact_points();
  if (pts)
    n = static_cast<Index>(pts->position->size());
  else if (const auto surf = parts[k]->contact_surface())
    n = static_cast<Index>(surf->node_position->size());
  const bool spins = pts && pts->angular_velocity;
  std::vector<Vec<D>>& force = out.force[k];
  std::vector<AxialVec<D>>& torque = out.torque[k];
  // A particle part's particles given a force are tracked in Coupling's own buffers (out's
  // marks sized for the part): then only those are zeroed again.
  std::vector<std::uint8_t>* marks = k < out.marked.size() ? &out.marked[k] : nullptr;
  const bool tracked = track && pts && marks;
  auto restart_marks = [&] {
    if (!marks) return;
    if (tracked)
      marks->assign(at(n), 0);
    else
      marks->clear();
    out.touched[k].clear();
  };
  // The buffers are kept from call to call: zeroed where written, or in one parallel pass,
  // reallocated when the count changes.
  if (static_cast<Index>(force.size()) != n || (spins && static_cast<Index>(torque.size()) != n)) {
    force.assign(at(n), Vec<D>::Zero());
    if (spins) torque.assign(at(n), axial_zero<D>());
    restart_marks();
    return;
  }
  if (tracked && marks->size() == at(n)) {
    for (const Index i : out.touched[k]) {
      force[at(i)] = Vec<D>::Zero();
      if (spins) torque[at(i)] = axial_zero<D>();
      (*marks)[at(i)] = 0;
    }
    out.touched[k].clear();
    return;
  }
  parallel::for_each(n, [&](Index i) {
    force[at(i)] = Vec<D>::Zero();
    if (spins) torque[at(i)] = axial_zero<D>();
  });
  restart_marks();
}

template <int D>
void Coupling<D>::apply(const PartList<D>& parts, Real dt_s) {
  compute(parts, dt_s);
  hand_over(parts);
}

template <int D>
void Coupling<D>::compute(const PartList<D>& parts, Real dt_s) {
  if (pairings_.empty()) return;
  // Forces per part in any contact: per particle, or per node of a surface.
  ContactForces<D>& out = forces_;
  out.force.resize(parts.size());
  out.torque.resize(parts.size());
  out.touched.resize(parts.size());
  out.marked.resize(parts.size());
  // On ranks, every contact over whole views of its parts; each part then takes its own share.
  // On one rank the particles given a force are tracked (hand_over() hands those over).
  const PartList<D>& on = spread_ ? spread_->refresh(parts) : parts;
  for (std::size_t k : involved_)
    size_for(on, k, out, !spread_);
  for (auto& p : pairings_)
    p->apply(on, dt_s, out);
  finish(on, all_);
}

template <int D>
void Coupling<D>::hand_over(const PartList<D>& parts) {
  if (pairings_.empty()) return;
  const PartList<D>& on = seen(parts);
  for (std::size_t k : involved_) {
    if (forces_.marked[k].empty()) {
      on[k]->add_contact_forces(forces_.force[k], forces_.torque[k]);
      continue;
    }
    std::vector<Index>& touched = forces_.touched[k];
    std::sort(touched.begin(), touched.end());
    on[k]->add_touched_contact_forces(forces_.force[k], forces_.torque[k], touched);
  }
  if (spread_) spread_->hand_back(parts);
}

template <int D>
void Coupling<D>::finish(const PartList<D>& on, const std::vector<std::size_t>& which) {
  // A contact whose views differ from rank to rank (a side's view marks its own particles)
  // has each pair on the rank that counts it: its totals are over the ranks. The others have
  // every pair on every rank.
  std::vector<ContactSums<D>*> here, over_ranks;
  for (const std::size_t c : which) {
    bool spread = false;
    for (const std::size_t k : sides(c))
      if (const auto p = on[k]->contact_points(); p && p->own) spread = true;
    (spread ? over_ranks : here).push_back(&pairings_[c]->sums());
  }
  finish_sums<D>(here, nullptr, nullptr);
  if (!spread_ || !spread_->owner_computed()) return;
  // The heads of the sums travel with the step limits of the state just evaluated, which the
  // next step takes when nothing they read has changed since (limits()): one gather for both.
  std::vector<Real> heads = sums_head<D>(over_ranks);
  std::vector<PairLimits> lim(pairings_.size());
  for (std::size_t c = 0; c < pairings_.size(); ++c)
    pairings_[c]->limit_step(on, lim[c]);
  spread_->agree(lim, &heads);
  limits_ = std::move(lim);
  limits_at_ = spread_->gathers();
  finish_sums<D>(over_ranks, &spread_->comm(), &heads);
}

template <int D>
void Coupling<D>::evaluate(const PartList<D>& parts, const std::vector<std::size_t>& which,
                           const std::vector<Real>& dt_s, std::vector<ContactForces<D>>& out) {
  // On ranks over whole views of the parts (Coupling::spread without zones), whose particles
  // take back the contact state the pairings leave.
  const PartList<D>& on = spread_ ? spread_->refresh(parts) : parts;
  out.resize(pairings_.size());
  std::vector<std::size_t> touched;
  for (std::size_t c : which) {
    out[c].force.resize(parts.size());
    out[c].torque.resize(parts.size());
    for (std::size_t k : sides(c)) {
      size_for(on, k, out[c], false);
      if (std::find(touched.begin(), touched.end(), k) == touched.end()) touched.push_back(k);
    }
    pairings_[c]->apply(on, dt_s[c], out[c]);
  }
  finish(on, which);
  if (!spread_) return;
  std::sort(touched.begin(), touched.end());
  for (std::size_t k : touched)
    spread_->hand_back_state(parts, k);
}

template <int D>
const PartList<D>& Coupling<D>::seen(const PartList<D>& parts) const {
  return spread_ ? spread_->views() : parts;
}

template <int D>
void Coupling<D>::hand_to(const PartList<D>& parts, std::size_t k, const std::vector<Vec<D>>& force,
                          const std::vector<AxialVec<D>>& torque, bool next) const {
  auto give = [&](const std::vector<Vec<D>>& f, const std::vector<AxialVec<D>>& t) {
    if (next)
      parts[k]->set_next_contact_forces(f, t);
    else
      parts[k]->add_contact_forces(f, t);
  };
  if (!spread_) return give(force, torque);
  // On ranks: the entries of the entities this rank holds.
  const parts::WholeLayout& layout = spread_->layout(k);
  give(parts::local_of_whole(layout, force),
       torque.empty() ? std::vector<AxialVec<D>>{} : parts::local_of_whole(layout, torque));
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
