// Contacts between parts spread over ranks; see spread_coupling.hpp.
#include "contact/spread_coupling.hpp"

#include "contact/contact_zone.hpp"
#include "core/axial_vec.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <type_traits>
#include <utility>

namespace crater::contact {

void refuse_stepping(const std::string& part, const char* what) {
  throw std::logic_error("whole contact view of part '" + part + "' does not step: " + what);
}

template <int D>
std::optional<parts::ContactPoints<D>> WholePart<D>::contact_points() const {
  if (!is_points_) return std::nullopt;
  auto& p = const_cast<Points&>(points_);  // the offsets are the contacts' to write
  parts::ContactPoints<D> v;
  v.position = &p.position;
  v.velocity = &p.velocity;
  v.mass = &p.mass;
  v.radius = &p.radius;
  if (p.spins) v.angular_velocity = &p.angular_velocity;
  if (p.offsets) {
    v.surface_offset = &p.surface_offset;
    v.surface_overlap = &p.surface_overlap;
  }
  if (p.ids) v.id = &p.id;
  if (zone_) {
    v.own = &p.own;
    v.whole_count = whole_count_;
    v.whole_lightest_kg = whole_lightest_kg_;
    v.whole_largest_radius_m = whole_largest_radius_m_;
  }
  return v;
}

template <int D>
unsigned WholePart<D>::unchanged(const parts::Part<D>& part,
                                 const parts::WholeLayout& layout) const {
  const auto local = part.contact_points();
  if (!is_points_ || !local || points_.position.size() != at(layout.whole_count)) return 0;
  const Points& p = points_;
  if (p.offsets != (local->surface_offset && local->surface_overlap) ||
      p.ids != (local->id != nullptr))
    return 0;
  // The view's whole values against this rank's own, bit for bit (a NaN never matches).
  auto holds = [&](const auto& whole, const auto& mine) {
    using T = std::decay_t<decltype(whole[0])>;
    for (const Index i : layout.owned)
      if (std::memcmp(&whole[at(layout.whole_of_local[at(i)])], &mine[at(i)], sizeof(T)) != 0)
        return false;
    return true;
  };
  unsigned same = 0;
  if (holds(p.mass, *local->mass) && (!p.ids || holds(p.id, *local->id))) same |= kMassId;
  if (holds(p.radius, *local->radius)) same |= kRadius;
  if (!p.offsets || (holds(p.surface_offset, *local->surface_offset) &&
                     holds(p.surface_overlap, *local->surface_overlap)))
    same |= kContactState;
  return same;
}

template <int D>
void WholePart<D>::assemble(const parallel::Comm& comm, const parts::Part<D>& part,
                            const parts::WholeLayout& layout, unsigned kept) {
  // Every field of the view in one all-gather.
  parts::WholeExchange x(layout);
  zone_ = false;
  if (const auto local = part.contact_points()) {
    is_points_ = true;
    Points& p = points_;
    p.spins = local->angular_velocity != nullptr;
    p.offsets = local->surface_offset && local->surface_overlap;
    p.ids = local->id != nullptr;
    const bool mass_id = !(kept & kMassId), radius = !(kept & kRadius),
               state = p.offsets && !(kept & kContactState);
    x.add(*local->position);
    x.add(*local->velocity);
    if (mass_id) x.add(*local->mass);
    if (radius) x.add(*local->radius);
    if (p.spins) x.add(*local->angular_velocity);
    if (state) {
      x.add(*local->surface_offset);
      x.add(*local->surface_overlap);
    }
    if (p.ids && mass_id) x.add(*local->id);
    x.exchange(comm);
    std::size_t f = 0;
    p.position = x.take<Vec<D>>(f++);
    p.velocity = x.take<Vec<D>>(f++);
    if (mass_id) p.mass = x.take<Real>(f++);
    if (radius) p.radius = x.take<Real>(f++);
    if (p.spins) p.angular_velocity = x.take<AxialVec<D>>(f++);
    if (state) {
      p.surface_offset = x.take<Real>(f++);
      p.surface_overlap = x.take<Real>(f++);
    }
    if (p.ids && mass_id) p.id = x.take<std::int64_t>(f++);
    return;
  }
  const auto local = part.contact_surface();
  if (!local) throw std::logic_error("part '" + part.name() + "' offers contacts nothing");
  // Only the nodes the whole surface reads travel (its faces' nodes; every node when the faces
  // are listed again); the others keep what they last held, alike on every rank, and nothing
  // reads them.
  const std::vector<Index>* needed = part.whole_surface_nodes();  // collective
  if (!needed) throw std::logic_error("part '" + part.name() + "' has no whole surface");
  const std::size_t whole = at(layout.whole_count);
  if (nodes_.position.size() != whole) {
    nodes_.position.assign(whole, Vec<D>::Zero());
    nodes_.velocity.assign(whole, Vec<D>::Zero());
    nodes_.mass.assign(whole, 0);
  }
  struct NodeRecord {
    std::int64_t node;
    std::array<Real, D> position, velocity;
    Real mass;
  };
  std::vector<NodeRecord> mine;
  // Which whole nodes travel, as flags (made again when the list is another).
  if (needed_of_ != *needed || needed_flag_.size() != whole) {
    needed_of_ = *needed;
    needed_flag_.assign(whole, 0);
    for (const Index w : *needed)
      needed_flag_[at(w)] = 1;
  }
  for (const Index i : layout.owned) {
    const Index w = layout.whole_of_local[at(i)];
    if (!needed_flag_[at(w)]) continue;
    NodeRecord& r = mine.emplace_back();
    r.node = w;
    for (int d = 0; d < D; ++d) {
      r.position[at(d)] = (*local->node_position)[at(i)][d];
      r.velocity[at(d)] = (*local->node_velocity)[at(i)][d];
    }
    r.mass = (*local->node_mass)[at(i)];
  }
  for (const NodeRecord& r : parallel::all_gather(comm, std::span<const NodeRecord>(mine))) {
    for (int d = 0; d < D; ++d) {
      nodes_.position[at(r.node)][d] = r.position[at(d)];
      nodes_.velocity[at(r.node)][d] = r.velocity[at(d)];
    }
    nodes_.mass[at(r.node)] = r.mass;
  }
  surface_ = part.whole_contact_surface(nodes_.position);
  if (!surface_) throw std::logic_error("part '" + part.name() + "' has no whole surface");
  surface_->node_position = &nodes_.position;
  surface_->node_velocity = &nodes_.velocity;
  surface_->node_mass = &nodes_.mass;
}

template <int D>
void WholePart<D>::hand_back(parts::Part<D>& part, const parts::WholeLayout& layout) const {
  if (zone_) {
    // Forces for the entities in the view alone (the part is told which: the others' are
    // zero). Torques for rotating particles even when the view is empty (no torque buffer then).
    const std::size_t n = view_of_local_.size();
    const std::size_t n_torque = points_.spins ? n : 0;
    if (hand_force_.size() != n || hand_torque_.size() != n_torque) {
      hand_force_.assign(n, Vec<D>::Zero());
      hand_torque_.assign(n_torque, axial_zero<D>());
    } else {
      for (const Index i : handed_) {
        hand_force_[at(i)] = Vec<D>::Zero();
        if (n_torque) hand_torque_[at(i)] = axial_zero<D>();
      }
    }
    for (const Index i : in_view_) {
      const Index k = view_of_local_[at(i)];
      hand_force_[at(i)] = force_[at(k)];
      if (n_torque && !torque_.empty()) hand_torque_[at(i)] = torque_[at(k)];
    }
    handed_ = in_view_;
    part.add_touched_contact_forces(hand_force_, hand_torque_, in_view_);
    if (!points_.offsets) return;
    const auto local = part.contact_points();
    for (std::size_t i = 0; i < n; ++i)
      if (const Index k = view_of_local_[i]; k >= 0) {
        (*local->surface_offset)[i] = points_.surface_offset[at(k)];
        (*local->surface_overlap)[i] = points_.surface_overlap[at(k)];
      } else {
        (*local->surface_offset)[i] = -1;
      }
    return;
  }
  const std::vector<AxialVec<D>> torque =
      torque_.empty() ? std::vector<AxialVec<D>>{} : parts::local_of_whole(layout, torque_);
  part.add_contact_forces(parts::local_of_whole(layout, force_), torque);
  hand_back_state(part, layout);
}

template <int D>
void WholePart<D>::hand_back_state(parts::Part<D>& part, const parts::WholeLayout& layout) const {
  if (zone_) throw std::logic_error("contacts: a zone's view hands back its state with forces");
  if (!is_points_ || !points_.offsets) return;
  const auto local = part.contact_points();
  for (std::size_t i = 0; i < layout.whole_of_local.size(); ++i) {
    const auto w = at(layout.whole_of_local[i]);
    (*local->surface_offset)[i] = points_.surface_offset[w];
    (*local->surface_overlap)[i] = points_.surface_overlap[w];
  }
}

template <int D>
SpreadContacts<D>::SpreadContacts(const parallel::Comm& comm, const PartList<D>& parts,
                                  std::vector<std::size_t> involved,
                                  std::vector<std::pair<std::size_t, std::size_t>> sides,
                                  std::vector<std::array<const SurfaceFilter<D>*, 2>> filters,
                                  bool zones)
    : comm_(comm),
      involved_(std::move(involved)),
      sides_(std::move(sides)),
      filters_(std::move(filters)),
      zones_allowed_(zones),
      owners_(parts.size()),
      zones_(parts.size()),
      layout_(parts.size(), nullptr),
      stamp_(parts.size()) {
  for (const auto& p : parts)
    whole_.push_back(std::make_unique<WholePart<D>>(p->name(), p->method()));
}

template <int D>
const PartList<D>& SpreadContacts<D>::refresh(const PartList<D>& parts) {
  ++gathers_;
  for (const std::size_t k : involved_) {
    layout_[k] = parts[k]->contact_layout();  // collective when rebuilt: every rank, in order
    if (!layout_[k])
      throw std::logic_error("part '" + parts[k]->name() + "' in a contact is not spread");
  }
  // The whole views first (surfaces, and the particle parts that are the smaller side of a
  // particle contact), then the contact zones, which read the surfaces' whole views.
  std::vector<std::size_t>& zoned = zoned_;
  zoned.clear();
  owner_computed_ = false;
  for (const std::size_t k : involved_) {
    if (zoned_view(parts, k)) {
      owner_computed_ = true;
      zoned.push_back(k);
      continue;
    }
    auto& whole = static_cast<WholePart<D>&>(*whole_[k]);
    // A particle view keeps the fields that no rank's own entities have changed since the last
    // gather (the same layout on every rank): one sum over the ranks of how many ranks changed
    // each group of fields (WholePart::Kept), a 20-bit digit per group.
    unsigned kept = 0;
    if (parts[k]->contact_points()) {
      const unsigned same =
          stamp_[k].same_layout(*layout_[k]) ? whole.unchanged(*parts[k], *layout_[k]) : 0;
      std::int64_t changed = 0;
      for (const unsigned bit : {1u, 2u, 4u})
        if (!(same & bit)) changed += std::int64_t{1} << (20 * std::countr_zero(bit));
      changed = comm_.sum(changed);
      for (const unsigned bit : {1u, 2u, 4u})
        if (((changed >> (20 * std::countr_zero(bit))) & ((1 << 20) - 1)) == 0) kept |= bit;
      if (kept & WholePart<D>::kMassId) ++static_kept_;
    }
    whole.assemble(comm_, *parts[k], *layout_[k], kept);
    stamp_[k].take(*parts[k], *layout_[k]);
  }
  for (const std::size_t k : zoned) {
    auto& whole = static_cast<WholePart<D>&>(*whole_[k]);
    const Real r_max = whole_largest_radius(comm_, *parts[k]->contact_points(), *layout_[k]);
    touching_of(parts, k, zone_of(parts, k, r_max), r_max);
    whole.assemble_zone(comm_, *parts[k], *layout_[k], zones_[k].to, r_max);
    stamp_[k].take(*parts[k], *layout_[k]);
    ++zone_views_;
    zone_particles_ += whole.view_count();
    zone_whole_ += layout_[k]->whole_count;
  }
  return whole_;
}

template <int D>
const PartList<D>& SpreadContacts<D>::for_limits(const PartList<D>& parts) {
  Real changed = 0;
  for (const std::size_t k : involved_) {
    const parts::WholeLayout* layout = parts[k]->contact_layout();  // collective when rebuilt
    if (!layout || layout != layout_[k] || !stamp_[k].same(*parts[k], *layout)) changed = 1;
  }
  // Every rank refreshes, or none: the gathers are collective.
  if (comm_.max(changed) > 0) return refresh(parts);
  ++reused_;
  return whole_;
}

template <int D>
void SpreadContacts<D>::Stamp::take(const parts::Part<D>& part, const parts::WholeLayout& layout) {
  valid = true;
  whole_of_local = layout.whole_of_local;
  owned = layout.owned;
  revision = 0;
  id.clear();
  if (const auto p = part.contact_points()) {
    position = *p->position;
    mass = *p->mass;
    if (p->id) id = *p->id;
  } else if (const auto s = part.contact_surface()) {
    position = *s->node_position;
    mass = *s->node_mass;
    revision = s->revision;
  }
}

template <int D>
bool SpreadContacts<D>::Stamp::same(const parts::Part<D>& part,
                                    const parts::WholeLayout& layout) const {
  if (!valid || layout.whole_of_local != whole_of_local) return false;
  // Bit for bit (a NaN never matches: such a state is refreshed).
  auto bits = [](const auto& a, const auto& b) {
    return a.size() == b.size() &&
           (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0);
  };
  if (const auto p = part.contact_points())
    return bits(*p->position, position) && bits(*p->mass, mass) &&
           (p->id ? bits(*p->id, id) : id.empty());
  if (const auto s = part.contact_surface())
    return s->revision == revision && bits(*s->node_position, position) &&
           bits(*s->node_mass, mass);
  return false;
}

template <int D>
void SpreadContacts<D>::hand_back(const PartList<D>& parts) const {
  for (const std::size_t k : involved_)
    static_cast<const WholePart<D>&>(*whole_[k]).hand_back(*parts[k], *layout_[k]);
}

template <int D>
void SpreadContacts<D>::hand_back_state(const PartList<D>& parts, std::size_t k) const {
  static_cast<const WholePart<D>&>(*whole_[k]).hand_back_state(*parts[k], *layout_[k]);
}

template class WholePart<2>;
template class WholePart<3>;
template class SpreadContacts<2>;
template class SpreadContacts<3>;

}  // namespace crater::contact
