// The DEM part's state as the solver reads and keeps it (dem_part_impl.hpp): fault checks,
// energies, diagnostics, the grains of a settled packing, outflow removal, and checkpoints.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>
#include <algorithm>
#include <array>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "dem/dem_part_impl.hpp"
#include "fields/spread.hpp"

namespace crater::dem::detail {
namespace {

template <int D>
Real angular_kinetic(Real inertia, const AngularVec<D>& w) {
  if constexpr (D == 2)
    return 0.5 * inertia * w * w;
  else
    return 0.5 * inertia * w.squaredNorm();
}

// An empty history slot's payload.
template <int D, class T>
T blank() {
  if constexpr (std::is_same_v<T, Vec<D>>)
    return Vec<D>::Zero();
  else if constexpr (std::is_same_v<T, AngularVec<D>>)
    return angular_zero<D>();
  else
    return T{};
}

}  // namespace

template <int D>
Real DemPart<D>::mass_kg() const {
  return total([&](Index i) { return m_[i]; });
}

template <int D>
std::optional<parts::Fault> DemPart<D>::local_check() const {
  const Index n = f_.size();
  if (overflow_ < n)
    return parts::Fault{id_[overflow_],
                        fmt::format("more than {} contacts on one grain: grains overlap far "
                                    "beyond what the contact law allows (time step too "
                                    "large or grains placed overlapping)",
                                    kMaxContacts)};
  if (bond_lost_ < n)
    return parts::Fault{id_[bond_lost_],
                        fmt::format("a bonded pair separated by more than {} x the largest "
                                    "radius without the bond breaking: its strength is far "
                                    "above what its stiffness allows",
                                    2 * kBondReach)};
  const Index bad = unhealthy_;  // note_health
  if (bad >= n) return std::nullopt;
  const Index i = bad;
  if (!leave_domain_ && !in_domain(i) && !through_absorbing_wall(i))
    return parts::Fault{id_[i], fmt::format("grain left the domain at x = ({}) m; enlarge "
                                            "[domain], add walls or set domain.outflow = "
                                            "\"remove\"",
                                            fmt::join(x_[i].data(), x_[i].data() + D, ", "))};
  if (!x_[i].allFinite())
    return parts::Fault{id_[i], fmt::format("non-finite position x = ({}) m",
                                            fmt::join(x_[i].data(), x_[i].data() + D, ", "))};
  return parts::Fault{id_[i], "non-finite force or torque"};
}

template <int D>
template <class Term>
Real DemPart<D>::total(Term&& term, Real extra) const {
  std::vector<Real> terms;
  terms.reserve(static_cast<std::size_t>(f_.size()) + 1);
  for (Index i = 0; i < f_.size(); ++i)
    if (!ghost(i)) terms.push_back(term(i));
  terms.push_back(extra);
  return parallel::reproducible_sum(comm_ ? *comm_ : parallel::Comm{}, terms);
}

// Sums over the grains by the reproducible sum: the same bits for any thread count, and for
// any rank count once the grains are spread over ranks (collective then).
template <int D>
parts::Energies DemPart<D>::energies() const {
  // The five sums in one pass over the grains, each with the bits total() gives it.
  const std::array<Real, 5> extra{0, 0, contact_dissipated_, local_dissipated_, external_work_};
  const std::array<Real, 5> sum = parallel::reproducible_sums<5>(
      comm_, f_.size(), [&](Index i) { return !ghost(i); },
      [&](Index i) {
        return std::array<Real, 5>{
            0.5 * m_[i] * v_[i].squaredNorm() + angular_kinetic<D>(inertia_[i], w_[i]), elastic_[i],
            work_contact_[i], work_damping_[i], work_external_[i]};
      },
      &extra);
  parts::Energies en;
  en.kinetic_j = sum[0];
  // Stored in the springs + lost in contacts, minus the work of contacts with other parts.
  en.contact_j = sum[1] + sum[2] - contact_.work_j;
  en.damping_j = sum[3];
  en.external_work_j = sum[4];
  en.eroded_j = outflow_.energy_j();
  return en;
}

template <int D>
std::vector<parts::Diagnostic> DemPart<D>::diagnostics() const {
  std::vector<parts::Diagnostic> d = diagnostics_;
  if (!cfg_.walls.empty() || !cfg_.absorbing_walls.empty())
    d.push_back(
        {"wall_reflections", total([&](Index i) { return reflections_[i]; }, wall_reflections_)});
  if (cfg_.bonds.enabled) {
    d.push_back({"bonds_initial", static_cast<Real>(bonds_initial_)});
    d.push_back({"bonds_broken", bonds_broken_});
  }
  if (outflow_remove_) outflow_.add_diagnostics(d);
  return d;
}

template <int D>
std::vector<Grain<D>> DemPart<D>::grains() const {
  std::vector<Grain<D>> g(static_cast<std::size_t>(f_.size()));
  for (Index i = 0; i < f_.size(); ++i)
    g[static_cast<std::size_t>(id_[i])] = {x_[i], r_[i]};
  return g;
}

template <int D>
std::pair<Real, Real> DemPart<D>::settling_measure() const {
  // Over the whole part (collective on ranks), each sum with the bits of one rank.
  const auto n = static_cast<Real>(std::max<Index>(count(), 1));
  const Real k = energies().kinetic_j / n;
  const Real m = mass_kg() / n;
  const Real r = total([&](Index i) { return r_[i]; }) / n;
  return {k, m * gravity_.norm() * r};
}

template <int D>
Real DemPart<D>::unbalanced_ratio() const {
  const Real f = total([&](Index i) { return force_[i].norm(); });
  return f / (mass_kg() * gravity_.norm());
}

// outflow = "remove" (and transmitting absorbing faces): grains beyond the domain box leave the
// model at the end of a step, with the velocities of t + dt, in batches: outflow_batch_steps_
// steps after the first grain of the batch went out, or at a frame (those that went out since,
// and are still out, leave with it). What they carried goes to eroded_j, so the balance still
// closes: their kinetic and rotational energy, and the energy stored in their contacts and
// bonds (elastic_ of the grains they end with), which would otherwise vanish from contact_j.
// The rest keep their order (compaction in index order) and their contact and bond histories
// (packed, less the slots keyed by a removed grain); the list is rebuilt at the next force
// stage, and until then the survivors' positions of the last build still give their order
// (VerletSkin::compacted): the same numbers for any thread count, and after a restart from
// this state.
// On ranks every rank marks its own grains and its ghosts (whose positions their owners sent at
// this force stage, so that every rank holding a grain decides alike); the own ones that leave
// are counted over every rank, and what they carried summed by the reproducible sum (one rank's
// bits on any number); the part's books of removed grains are the root's (energies() adds each
// rank's).
template <int D>
void DemPart<D>::remove_outflow() {
  const Index n = f_.size();
  const bool frame = std::exchange(frame_step_, false);
  outflow_.mark(n, [&](Index i) { return stays(i); });
  const parallel::Comm one;
  const parallel::Comm& comm = comm_ ? *comm_ : one;
  const parts::OutflowTally gone = outflow_.tally(comm, n, [&](Index i) { return !ghost(i); });
  if (gone.count == 0) {
    outflow_wait_ = 0;
    return;
  }
  // Until the batch is due, the leaving grains move on beyond the face (nothing acts on them
  // there but their contacts and gravity), booked as the part's; frames show none of them.
  if (++outflow_wait_ < outflow_batch_steps_ && !frame) return;
  outflow_wait_ = 0;
  const std::vector<Real> lost = unhook_leaving();
  // What the leaving grains carried, and what the staying ones' contacts with them held.
  const std::vector<Index> holding = parallel::select(n, [&](Index i) { return lost[at(i)] != 0; });
  std::vector<Real> energy(gone.own.size() + holding.size());
  for (std::size_t q = 0; q < gone.own.size(); ++q) {
    const Index i = gone.own[q];
    energy[q] =
        0.5 * m_[i] * v_[i].squaredNorm() + angular_kinetic<D>(inertia_[i], w_[i]) + elastic_[i];
  }
  for (std::size_t q = 0; q < holding.size(); ++q)
    energy[gone.own.size() + q] = lost[at(holding[q])];
  const parts::Removed left{gone.sum(comm, [&](Index i) { return m_[i]; }),
                            parallel::reproducible_sum(comm, std::span<const Real>(energy))};
  outflow_.book(name_, "grains", time_s_, gone.count, left,
                leave_domain_ ? (cfg_.absorbing_walls.empty()
                                     ? "domain.outflow = \"remove\""
                                     : "domain.outflow = \"remove\"; absorbing walls transmit")
                              : "absorbing walls transmit");
  // The leaving grains' work books stay with the part (the root's on ranks).
  const Real external = gone.sum(comm, [&](Index i) { return work_external_[i]; });
  const Real contact = gone.sum(comm, [&](Index i) { return work_contact_[i]; });
  const Real damping = gone.sum(comm, [&](Index i) { return work_damping_[i]; });
  const Real reflections = gone.sum(comm, [&](Index i) { return reflections_[i]; });
  if (comm.root()) {
    external_work_ += external;
    contact_dissipated_ += contact;
    local_dissipated_ += damping;
    wall_reflections_ += reflections;
  }
  compact_survivors();
}

// A staying grain's contacts and bonds with leaving ones (outflow_'s mark): the energy of those
// it owns leaves with them (the others' is in the leaving grain's elastic_; returned per grain,
// and taken off its elastic_), and their forces leave its force_ and torque_ (undoing
// grain_pass), so that the next half kick owes nothing to a removed grain (exactly so without
// local damping, which acted on the sum). Ghosts are their owners' to correct.
template <int D>
std::vector<Real> DemPart<D>::unhook_leaving() {
  std::vector<Real> lost(static_cast<std::size_t>(f_.size()), 0);
  // The staying own grains with a pair of a leaving one (the partners of its pairs, the owners
  // of the pairs it receives), ascending: the others have nothing to undo.
  std::vector<Index> touched;
  for (const Index j : parallel::select(f_.size(), [&](Index k) { return !outflow_.kept(k); })) {
    const auto uj = static_cast<std::size_t>(j);
    for (auto k = static_cast<std::size_t>(pair_begin_[uj]); k < at(pair_begin_[uj + 1]); ++k)
      touched.push_back(pair_j_[k]);
    for (auto e = static_cast<std::size_t>(recv_begin_[uj]); e < at(recv_begin_[uj + 1]); ++e)
      touched.push_back(pair_owner(static_cast<std::size_t>(recv_pair_[e])));
  }
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  parallel::for_each(static_cast<Index>(touched.size()), [&](Index q) {
    const Index i = touched[at(q)];
    if (!outflow_.kept(i) || ghost(i)) return;
    Real held = 0;
    const auto own_first = static_cast<std::size_t>(pair_begin_[static_cast<std::size_t>(i)]);
    const auto own_last = static_cast<std::size_t>(pair_begin_[static_cast<std::size_t>(i) + 1]);
    for (std::size_t k = own_first; k < own_last; ++k) {
      if (outflow_.kept(pair_j_[k])) continue;
      const std::uint8_t flags = cache_.flags[k];
      if (flags) held += cache_.elastic[k];
      if (flags & kContactOn) {
        force_[i] -= cache_.contact[k].f1;
        torque_[i] -= cache_.t1[k];
        contacts_[i] -= 1;  // it counts the contacts it owns (and its walls)
      }
      if (flags & kBondOn) {
        force_[i] -= cache_.bond_f1[k];
        torque_[i] -= cache_.bond_t1[k];
        bonds_[i] -= 1;
      }
    }
    const auto first = static_cast<std::size_t>(recv_begin_[static_cast<std::size_t>(i)]);
    const auto last = static_cast<std::size_t>(recv_begin_[static_cast<std::size_t>(i) + 1]);
    for (std::size_t e = first; e < last; ++e) {
      const auto k = static_cast<std::size_t>(recv_pair_[e]);
      if (outflow_.kept(pair_owner(k))) continue;
      const std::uint8_t flags = cache_.flags[k];
      if (flags & kContactOn) {
        force_[i] += cache_.contact[k].f1;
        torque_[i] -= cache_.contact[k].t2;
      }
      if (flags & kBondOn) {
        force_[i] += cache_.bond_f1[k];
        torque_[i] -= cache_.bond_t2[k];
        bonds_[i] -= 1;
      }
    }
    elastic_[i] -= held;
    lost[at(i)] = held;
  });
  return lost;
}

// The leaving grains (outflow_'s mark) leave the arrays, the slots of their contacts and bonds,
// and on ranks the ghost flags and the exchange lists; the lists wait for the next force stage.
template <int D>
void DemPart<D>::compact_survivors() {
  std::vector<std::int64_t> gone;  // ids of the leaving grains (ghosts too), sorted
  for (const Index i : parallel::select(f_.size(), [&](Index k) { return !outflow_.kept(k); }))
    gone.push_back(id_[i]);
  std::sort(gone.begin(), gone.end());
  if (!packed_) pack_history(partner_, xi_, roll_);
  packed_ = true;
  compact_slots(partner_, gone, xi_, roll_);
  compact_slots(bond_partner_, gone, bond_);
  const Index count = f_.size();
  const Index kept = outflow_.compact(f_);
  // The first failing grain of the last force stage, else the count (none: the run goes on).
  for (Index* first : {&overflow_, &bond_lost_, &unhealthy_})
    if (*first >= count) *first = kept;
  if (comm_) fields::compact_exchange(outflow_.survivors(), ghost_, halo_send_, halo_recv_);
  resize_bond_scratch();
  clear_wall_slots();
  skin_.compacted(outflow_.survivors());
  contact_extremes_at_ = -1;
  step_at_ = -1;
  contact_layout_builds_ = -1;  // the whole bed has fewer grains
}

// The kMaxContacts slots of each kept grain (outflow_.survivors()), in order, less the slots keyed
// by a grain in `gone` (its contacts and bonds end with it); the others move up, so that a grain's
// slots stay filled from the first. `payload` moves with `key` (empty vectors: models that
// are off).
template <int D>
template <class... Payload>
void DemPart<D>::compact_slots(std::vector<std::int64_t>& key, std::span<const std::int64_t> gone,
                               std::vector<Payload>&... payload) {
  if (key.empty()) return;
  constexpr auto slots = static_cast<std::size_t>(kMaxContacts);
  const std::span<const std::uint8_t> keep = outflow_.survivors();
  const std::vector<Index> kept =
      parallel::select(static_cast<Index>(keep.size()), [&](Index i) { return keep[at(i)] != 0; });
  // Where each new slot comes from (-1: emptied), per kept grain in parallel; then key and
  // payloads gathered by it.
  std::vector<std::int64_t> from(kept.size() * slots, -1);
  parallel::for_each(static_cast<Index>(kept.size()), [&](Index q) {
    std::size_t k = at(q) * slots;
    for (std::size_t s = 0; s < slots; ++s) {
      const std::size_t src = at(kept[at(q)]) * slots + s;
      const std::int64_t p = key[src];
      if (p == kNoContact) break;
      if (std::binary_search(gone.begin(), gone.end(), p)) continue;
      from[k++] = static_cast<std::int64_t>(src);
    }
  });
  auto gather = [&](auto& v, const auto& empty) {
    if (v.empty()) return;
    std::remove_reference_t<decltype(v)> out(from.size());
    parallel::for_each(static_cast<Index>(from.size()), [&](Index k) {
      const std::int64_t src = from[at(k)];
      out[at(k)] = src >= 0 ? v[static_cast<std::size_t>(src)] : empty;
    });
    v.swap(out);
  };
  gather(key, kNoContact);
  (gather(payload, blank<D, Payload>()), ...);
}

// The grain that owns pair k (a binary search in pair_begin_; outflow only).
template <int D>
Index DemPart<D>::pair_owner(std::size_t k) const {
  const auto it = std::upper_bound(pair_begin_.begin(), pair_begin_.end(), static_cast<Index>(k));
  return static_cast<Index>(it - pair_begin_.begin()) - 1;
}

template <int D>
template <class Archive, class Self, class Skin, class BondPartner, class Bond>
void DemPart<D>::archive_bonds_and_ledgers(Archive& a, Self& s, Skin& skin,
                                           BondPartner& bond_partner, Bond& bond) {
  a.vector(bond_partner);
  a.vector(bond);
  a.value(s.contact_.last_dt_s);
  a.value(s.bond_lost_);
  a.value(s.bonds_initial_);
  a.value(s.bonds_broken_);
  a.value(s.external_work_);
  a.value(s.contact_dissipated_);
  a.value(s.local_dissipated_);
  a.value(s.contact_.work_j);
  a.value(s.contact_.pending);
  a.value(s.wall_reflections_);
  a.block(skin);
  a.block(s.outflow_);
  a.value(s.outflow_wait_);
  // Moving walls (only then: the other parts' checkpoints are unchanged).
  if (!s.moving_.empty()) a.vector(s.moving_);
}

template <int D>
void DemPart<D>::save_state(parts::StateWriter& w) const {
  if (comm_) {
    save_gathered(w);
    return;
  }
  w.tag("dem");
  f_.save(w);
  if (packed_) {
    w.vector(partner_);
    w.vector(xi_);
    w.vector(roll_);
  } else {
    std::vector<std::int64_t> partner;
    std::vector<Vec<D>> xi;
    std::vector<AngularVec<D>> roll;
    pack_history(partner, xi, roll);
    w.vector(partner);
    w.vector(xi);
    w.vector(roll);
  }
  archive_bonds_and_ledgers(w, *this, skin_, bond_partner_, bond_);
}

template <int D>
void DemPart<D>::load_state(parts::StateReader& r) {
  r.tag("dem");
  moved_sq_ = -1;  // measured again at the next force stage
  contact_extremes_at_ = -1;
  step_at_ = -1;
  f_.load(r);
  r.vector(partner_);
  r.vector(xi_);
  r.vector(roll_);
  packed_ = true;
  const std::size_t moving = moving_.size();
  archive_bonds_and_ledgers(r, *this, skin_, bond_partner_, bond_);
  resize_bond_scratch();
  if (moving_.size() != moving) r.fail("it holds another number of moving walls");
  set_wall_planes();
  if (skin_.listed()) build_lists();
}

#define CRATER_DEM_STATE(D)                                                    \
  template std::optional<parts::Fault> DemPart<D>::local_check() const;        \
  template Real DemPart<D>::mass_kg() const;                                   \
  template parts::Energies DemPart<D>::energies() const;                       \
  template std::vector<parts::Diagnostic> DemPart<D>::diagnostics() const;     \
  template std::vector<Grain<D>> DemPart<D>::grains() const;                   \
  template std::pair<Real, Real> DemPart<D>::settling_measure() const;         \
  template Real DemPart<D>::unbalanced_ratio() const;                          \
  template void DemPart<D>::remove_outflow();                                  \
  template std::vector<Real> DemPart<D>::unhook_leaving();                     \
  template void DemPart<D>::compact_survivors();                               \
  template Index DemPart<D>::pair_owner(std::size_t) const;                    \
  template void DemPart<D>::save_state(parts::StateWriter&) const;             \
  template void DemPart<D>::load_state(parts::StateReader&);                   \
  template void DemPart<D>::archive_bonds_and_ledgers(                         \
      parts::StateWriter&, const DemPart<D>&, const neighbors::VerletSkin<D>&, \
      const std::vector<std::int64_t>&, const std::vector<ParallelBondState<D>>&);
CRATER_DEM_STATE(2)
CRATER_DEM_STATE(3)
#undef CRATER_DEM_STATE

}  // namespace crater::dem::detail
