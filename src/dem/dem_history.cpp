// The DEM part's neighbour lists and contact histories (dem_part_impl.hpp).
//
// Contact histories live with the contacts while the list stands: per owned pair (pair_xi_,
// pair_roll_) and per grain and wall (wall_xi_, wall_roll_), updated in place by the one
// thread that evaluates the contact, as LAMMPS keeps its history with the neighbour list. At
// a rebuild (and in a restart file) they are packed into kMaxContacts slots per grain keyed
// by the partner's id (partner_, xi_, roll_; walls: -1 - face; the fixed bodies of settling: -7 -
// their number), which survive the re-sort, and unpacked into the new list. A contact that is not
// touching holds a zero history.
#include <algorithm>
#include <span>
#include <vector>

#include "dem/dem_part_impl.hpp"
#include "neighbors/cell_grid.hpp"

namespace crater::dem::detail {
namespace {

// Moves the `slots` slots of each grain with it (empty vectors: models that are off), through
// `scratch`, which then holds the old order (kept for its storage: no copy, no allocation).
template <int Slots, class T>
void permute_blocks(std::vector<T>& slots, std::vector<T>& scratch, std::span<const Index> order) {
  if (slots.empty()) return;
  scratch.resize(slots.size());
  parallel::for_each(static_cast<Index>(order.size()), [&](Index i) {
    const auto to = static_cast<std::size_t>(i) * Slots;
    const auto from = static_cast<std::size_t>(order[static_cast<std::size_t>(i)]) * Slots;
    for (std::size_t k = 0; k < static_cast<std::size_t>(Slots); ++k)
      scratch[to + k] = slots[from + k];
  });
  for (std::size_t k = order.size() * Slots; k < slots.size(); ++k)
    scratch[k] = slots[k];  // slots of no grain in `order` (none, as called) stay
  slots.swap(scratch);
}

}  // namespace

// Verlet list with a skin, as in the SPH part; grains are re-sorted at each rebuild and the
// history slots move with them.
template <int D>
void DemPart<D>::update_neighbors() {
  const Real need = 2 * r_max_ * (cfg_.bonds.enabled ? 1 + kBondReach : 1);
  // advance measured the displacement; at the start and after a restart it is measured here.
  const bool stale = moved_sq_ >= 0 ? skin_.stale_given(moved_sq_, f_.size(), need)
                                    : skin_.stale(std::span<const Vec<D>>(x_), need);
  moved_sq_ = -1;
  // On ranks, all rebuild when one must: the decision of one rank holding every grain.
  const bool rebuild = comm_ ? comm_->max(stale ? 1.0 : 0.0) > 0 : stale;
  if (!rebuild) return;
  if (!packed_) pack_history(partner_, xi_, roll_);
  packed_ = true;
  if (comm_) redistribute(need * (1 + kSkin));  // the list's reach (VerletSkin::built)
  // Within a cell by id: the order then depends only on the grains' positions and ids
  // (cell_sort_order), the same for a rank's share of the bed and its ghosts as on one rank.
  const auto order = neighbors::cell_sort_order<D>(std::span<const Vec<D>>(x_), need * (1 + kSkin),
                                                   std::span<const std::int64_t>(id_));
  f_.permute(order);
  permute_slots(order);
  if (comm_) reorder_halo(order);
  skin_.built(std::span<const Vec<D>>(x_), need);
  build_lists();
}

// The list for the positions of the last rebuild (after a restart: the saved ones, which
// gives the very list the interrupted run used), its owned pairs, and the packed histories
// unpacked into them.
template <int D>
void DemPart<D>::build_lists() {
  neighbors::build_neighbor_list<D>(skin_.positions(), skin_.radius(), neighbors::Pairs::Full,
                                    list_);
  const Index n = list_.size();
  // Owned pairs: the entries (i, j) with id_i < id_j, per grain in list order; on ranks, not
  // those of two ghosts (no rank needs them).
  const bool ghosts = !ghost_.empty();
  auto kept = [&](Index i, Index j) { return !ghosts || !(ghost_[at(i)] & ghost_[at(j)]); };
  pair_begin_.assign(static_cast<std::size_t>(n) + 1, 0);
  recv_begin_.assign(static_cast<std::size_t>(n) + 1, 0);
  parallel::for_each(n, [&](Index i) {
    Index owned = 0, received = 0;
    for (const Index j : list_.of(i)) {
      if (!kept(i, j)) continue;
      owned += id_[i] < id_[j];
      received += id_[j] < id_[i];
    }
    pair_begin_[static_cast<std::size_t>(i) + 1] = owned;
    recv_begin_[static_cast<std::size_t>(i) + 1] = received;
  });
  for (Index i = 0; i < n; ++i) {
    pair_begin_[static_cast<std::size_t>(i) + 1] += pair_begin_[static_cast<std::size_t>(i)];
    recv_begin_[static_cast<std::size_t>(i) + 1] += recv_begin_[static_cast<std::size_t>(i)];
  }
  pair_j_.resize(static_cast<std::size_t>(pair_begin_.back()));
  parallel::for_each(n, [&](Index i) {
    Index p = pair_begin_[static_cast<std::size_t>(i)];
    for (const Index j : list_.of(i))
      if (id_[i] < id_[j] && kept(i, j)) pair_j_[static_cast<std::size_t>(p++)] = j;
  });
  // The pairs (j, i) that grain i receives (pairs are ascending in j's
  // row: binary search).
  recv_pair_.resize(pair_j_.size());
  parallel::for_each(n, [&](Index i) {
    Index e = recv_begin_[static_cast<std::size_t>(i)];
    for (const Index j : list_.of(i)) {
      if (id_[i] < id_[j] || !kept(i, j)) continue;
      const auto b = pair_j_.begin() + pair_begin_[static_cast<std::size_t>(j)];
      const auto it =
          std::lower_bound(b, pair_j_.begin() + pair_begin_[static_cast<std::size_t>(j) + 1], i);
      recv_pair_[static_cast<std::size_t>(e++)] = static_cast<Index>(it - pair_j_.begin());
    }
    // In pair order: the order in which a single thread meets them (scatter_).
    std::sort(recv_pair_.begin() + recv_begin_[static_cast<std::size_t>(i)],
              recv_pair_.begin() + e);
  });
  scatter_ = parallel::max_threads() == 1 && bond_partner_.empty() && !outflow_remove_;
  received_.clear();
  if (scatter_) {
    received_.resize(static_cast<std::size_t>(n));
    for (Index i = 0; i < n; ++i)
      received_[static_cast<std::size_t>(i)].force = m_[i] * gravity_;
  }
  const auto pairs = pair_j_.size();
  cache_.resize(pairs, !bond_partner_.empty(), outflow_remove_);
  pair_xi_.resize(pairs);
  pair_roll_.resize(rolling_.friction > 0 ? pairs : 0);
  tally_.resize(static_cast<std::size_t>(n));
  unpack_history();
  packed_ = false;
}

// The live contacts of each grain in the order pair_pass and grain_pass meet them (owned pairs
// in list order, then walls), into its kMaxContacts slots.
template <int D>
void DemPart<D>::pack_history(std::vector<std::int64_t>& partner, std::vector<Vec<D>>& xi,
                              std::vector<AngularVec<D>>& roll) const {
  const Index n = f_.size();
  // Sized here, filled below per grain (its slots past the last contact emptied there).
  partner.resize(static_cast<std::size_t>(n) * kMaxContacts);
  xi.resize(static_cast<std::size_t>(n) * kMaxContacts);
  if (rolling_.friction > 0)
    roll.resize(static_cast<std::size_t>(n) * kMaxContacts);
  else
    roll.clear();
  const bool pairs = static_cast<Index>(pair_begin_.size()) == n + 1;
  const std::size_t walls = wall_planes_.size();
  parallel::for_each(n, [&](Index i) {
    const std::size_t base = static_cast<std::size_t>(i) * kMaxContacts;
    std::size_t k = 0;
    auto put = [&](std::int64_t key, const Vec<D>& h, const AngularVec<D>& r) {
      if (k == kMaxContacts) return;  // only after an overflow fault (check())
      partner[base + k] = key;
      xi[base + k] = h;
      if (!roll.empty()) roll[base + k] = r;
      ++k;
    };
    if (pairs)
      for (Index p = pair_begin_[static_cast<std::size_t>(i)];
           p < pair_begin_[static_cast<std::size_t>(i) + 1]; ++p) {
        const auto q = static_cast<std::size_t>(p);
        if (!(cache_.flags[q] & kContactOn)) continue;
        put(id_[pair_j_[q]], pair_xi_[q], pair_roll_.empty() ? angular_zero<D>() : pair_roll_[q]);
      }
    for (std::size_t w = 0; w < walls; ++w) {
      const std::size_t at = static_cast<std::size_t>(i) * walls + w;
      if (!(wall_live_[static_cast<std::size_t>(i)] >> w & 1u)) continue;
      put(wall_key(w), wall_xi_[at], wall_roll_.empty() ? angular_zero<D>() : wall_roll_[at]);
    }
    for (; k < static_cast<std::size_t>(kMaxContacts); ++k) {
      partner[base + k] = kNoContact;
      xi[base + k] = Vec<D>::Zero();
      if (!roll.empty()) roll[base + k] = angular_zero<D>();
    }
  });
}

// The histories of partner_, xi_, roll_ into the pairs of the current list and the walls.
template <int D>
void DemPart<D>::unpack_history() {
  const Index n = f_.size();
  const std::size_t walls = wall_planes_.size();
  parallel::for_each(n, [&](Index i) {
    const std::size_t base = static_cast<std::size_t>(i) * kMaxContacts;
    for (Index p = pair_begin_[static_cast<std::size_t>(i)];
         p < pair_begin_[static_cast<std::size_t>(i) + 1]; ++p) {
      const auto q = static_cast<std::size_t>(p);
      const int k = find_slot(i, id_[pair_j_[q]]);
      // Live: the flag pack_history reads, until pair_pass sets it again.
      cache_.flags[q] = k < 0 ? 0 : kContactOn;
      pair_xi_[q] = k < 0 ? Vec<D>::Zero() : xi_[base + static_cast<std::size_t>(k)];
      if (!pair_roll_.empty())
        pair_roll_[q] = k < 0 ? angular_zero<D>() : roll_[base + static_cast<std::size_t>(k)];
    }
    wall_live_[static_cast<std::size_t>(i)] = 0;
    for (std::size_t w = 0; w < walls; ++w) {
      const std::size_t at = static_cast<std::size_t>(i) * walls + w;
      const int k = find_slot(i, wall_key(w));
      if (k >= 0) wall_live_[static_cast<std::size_t>(i)] |= 1u << w;
      wall_xi_[at] = k < 0 ? Vec<D>::Zero() : xi_[base + static_cast<std::size_t>(k)];
      if (!wall_roll_.empty())
        wall_roll_[at] = k < 0 ? angular_zero<D>() : roll_[base + static_cast<std::size_t>(k)];
    }
  });
}

template <int D>
ContactHistory<D> DemPart<D>::contact_history() const {
  std::vector<std::int64_t> partner;
  std::vector<Vec<D>> xi;
  std::vector<AngularVec<D>> roll;
  if (packed_) {
    partner = partner_;
    xi = xi_;
    roll = roll_;
  } else {
    pack_history(partner, xi, roll);
  }
  constexpr auto slots = static_cast<std::size_t>(kMaxContacts);
  const auto n = static_cast<std::size_t>(f_.size());
  ContactHistory<D> h;
  h.slots = kMaxContacts;
  h.partner.assign(n * slots, kNoContact);
  h.xi.assign(n * slots, Vec<D>::Zero());
  if (!roll.empty()) h.roll.assign(n * slots, angular_zero<D>());
  const std::int64_t first_body = wall_key(cfg_.walls.size());  // the bodies' keys are below
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t to = static_cast<std::size_t>(id_[static_cast<Index>(i)]) * slots;
    std::size_t k = 0;
    for (std::size_t s = 0; s < slots; ++s) {
      const std::int64_t p = partner[i * slots + s];
      if (p == kNoContact) break;
      if (p <= first_body) continue;
      h.partner[to + k] = p;
      h.xi[to + k] = xi[i * slots + s];
      if (!roll.empty()) h.roll[to + k] = roll[i * slots + s];
      ++k;
    }
  }
  return h;
}

template <int D>
void DemPart<D>::start_from(const ContactHistory<D>& h) {
  const auto n = static_cast<std::size_t>(f_.size()) * kMaxContacts;
  if (h.slots != kMaxContacts || h.partner.size() != n || h.xi.size() != n ||
      !(h.roll.empty() || h.roll.size() == n))
    throw std::logic_error("dem: contact histories for another part");
  partner_ = h.partner;
  xi_ = h.xi;
  // Rolling moments only when this part has rolling resistance (else none are kept).
  if (rolling_.friction > 0)
    roll_ = h.roll.empty() ? std::vector<AngularVec<D>>(n, angular_zero<D>()) : h.roll;
  else
    roll_.clear();
  packed_ = true;
}

// Slot of `partner` in grain i's packed history (partner_), or -1.
template <int D>
int DemPart<D>::find_slot(Index owner, std::int64_t partner) const {
  const std::size_t base = static_cast<std::size_t>(owner) * kMaxContacts;
  // Slots are filled from the first, the rest hold kNoContact: stop at the first empty one.
  for (int k = 0; k < kMaxContacts; ++k) {
    const std::int64_t p = partner_[base + static_cast<std::size_t>(k)];
    if (p == partner) return k;
    if (p == kNoContact) break;
  }
  return -1;
}

template <int D>
void DemPart<D>::permute_slots(std::span<const Index> order) {
  permute_blocks<kMaxContacts>(partner_, scratch_ids_, order);
  permute_blocks<kMaxContacts>(xi_, scratch_xi_, order);
  permute_blocks<kMaxContacts>(roll_, scratch_roll_, order);
  permute_blocks<kMaxContacts>(bond_partner_, scratch_ids_, order);
  std::vector<ParallelBondState<D>> bonds;
  permute_blocks<kMaxContacts>(bond_, bonds, order);
}

#define CRATER_DEM_HISTORY(D)                                                              \
  template void DemPart<D>::update_neighbors();                                            \
  template void DemPart<D>::build_lists();                                                 \
  template void DemPart<D>::pack_history(std::vector<std::int64_t>&, std::vector<Vec<D>>&, \
                                         std::vector<AngularVec<D>>&) const;               \
  template void DemPart<D>::unpack_history();                                              \
  template int DemPart<D>::find_slot(Index, std::int64_t) const;                           \
  template void DemPart<D>::permute_slots(std::span<const Index>);                         \
  template ContactHistory<D> DemPart<D>::contact_history() const;                          \
  template void DemPart<D>::start_from(const ContactHistory<D>&);
CRATER_DEM_HISTORY(2)
CRATER_DEM_HISTORY(3)
#undef CRATER_DEM_HISTORY

}  // namespace crater::dem::detail
