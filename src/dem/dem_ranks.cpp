// The DEM part on several ranks (issue 29, docs/distributed.md, "The DEM part on ranks").
//
// Each rank owns the grains of its box of a recursive coordinate bisection (the cuts made once,
// from the whole bed, parallel::RcbTree) and holds, beside them, copies of the other ranks'
// grains within the neighbour list's reach of its own (ghosts), in the same arrays. Owned grains
// and ghosts are sorted together in the canonical cell order (cell_sort_order by id), so every
// list row, and every sum of a grain's forces, runs over the same partners in the same order as
// on one rank. A pair across a cut is evaluated by both ranks, each from the same numbers: the
// pair's body 1 (the lower id) holds its history on both, so both get the same force bit for bit.
// Ghosts are never integrated; their motion comes from their owner at every force stage.
//
// At each rebuild of the lists (a global decision: the largest displacement over all ranks):
//   1. the ghosts go;
//   2. grains whose position now lies in another rank's box move to it with all their fields
//      and their packed contact histories (partner ids and springs), which then survive the move;
//   3. each rank sends the others copies of its grains within reach of their boxes, with their
//      histories (a ghost of lower id than its owned partner evaluates their contact);
//   4. all are sorted in the canonical order and the lists are built.
// Pairs of two ghosts are left out of the lists: no rank needs them.
#include <cstring>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "dem/dem_part_impl.hpp"
#include "fields/exchange.hpp"
#include "fields/spread.hpp"
#include "neighbors/cell_grid.hpp"
#include "parts/on_ranks.hpp"
#include "parts/state_archive.hpp"

namespace crater::dem::detail {
namespace {

template <int D>
constexpr std::size_t kAngular = D == 2 ? 1 : 3;

// Reals of a vector or an angular vector (a Real in 2D).
template <int D>
const Real* reals(const Vec<D>& v) {
  return v.data();
}
template <int D>
Real* reals(Vec<D>& v) {
  return v.data();
}
inline const Real* reals(const Real& v) {
  return &v;
}
inline Real* reals(Real& v) {
  return &v;
}
template <int D>
const Real* angular_reals(const AngularVec<D>& w) {
  if constexpr (D == 2)
    return &w;
  else
    return w.data();
}
template <int D>
Real* angular_reals(AngularVec<D>& w) {
  if constexpr (D == 2)
    return &w;
  else
    return w.data();
}

void put(std::vector<std::byte>& out, const void* p, std::size_t bytes) {
  const std::size_t at = out.size();
  out.resize(at + bytes);
  if (bytes) std::memcpy(out.data() + at, p, bytes);
}

// Reads bytes off the front of a received message.
struct Reader {
  std::span<const std::byte> in;
  std::size_t at = 0;
  void get(void* p, std::size_t bytes) {
    if (at + bytes > in.size()) throw std::logic_error("dem ranks: a message is cut short");
    if (bytes) std::memcpy(p, in.data() + at, bytes);
    at += bytes;
  }
  std::span<const std::byte> take(std::size_t bytes) {
    if (at + bytes > in.size()) throw std::logic_error("dem ranks: a message is cut short");
    const auto s = in.subspan(at, bytes);
    at += bytes;
    return s;
  }
};

}  // namespace

template <int D>
void DemPart<D>::distribute(const parallel::Comm& comm) {
  if (comm_) throw std::logic_error("dem: distribute() twice");
  // A settling bed (dem::settle_grains on ranks) is spread too: its fixed bodies (the regions
  // carved around) take wall slots, whose histories travel with the grains as the walls' do.
  comm_ = &comm;
  // The part's books of grains removed are the root's: energies() and diagnostics() add every
  // rank's (every rank has just built, or restored, the whole part's).
  if (!comm.root())
    external_work_ = contact_dissipated_ = local_dissipated_ = wall_reflections_ = 0;
  if (!packed_) pack_history(partner_, xi_, roll_);
  packed_ = true;
  if (skin_.radius() > 0 && skin_.positions().size() == static_cast<std::size_t>(f_.size())) {
    distribute_restored();
    return;
  }
  // Every rank holds the whole bed now: the same cuts everywhere, weighted by count.
  const std::vector<Real> weight(static_cast<std::size_t>(f_.size()), 1.0);
  cuts_ = parallel::rcb_tree<D>(std::span<const Vec<D>>(x_), weight, comm.size());
  std::vector<std::uint8_t> keep(static_cast<std::size_t>(f_.size()));
  for (Index i = 0; i < f_.size(); ++i)
    keep[at(i)] = cuts_.owner(x_[i]) == comm.rank();
  keep_grains(keep);
  ghost_.assign(static_cast<std::size_t>(f_.size()), 0);
  halo_send_.assign(static_cast<std::size_t>(comm.size()), {});
  halo_recv_.assign(static_cast<std::size_t>(comm.size()), {});
  resize_bond_scratch();
  skin_.invalidate();  // the first force stage builds the lists, and the ghosts
  moved_sq_ = -1;
}

// A part restored from a checkpoint, with the lists of the run that wrote it: the shares, the
// ghosts and the lists are made from the positions at that build (skin_.positions()), as the
// ranks would have made them then, so that the next rebuild comes at the same step as in the
// run that was not interrupted. Every rank holds the whole part: no message is needed. A
// checkpoint written between a removal of grains and the next force stage holds the survivors'
// positions of the build without a list (VerletSkin::compacted): the shares and ghosts are made
// from them, and the lists are left to that force stage, as in the run that wrote it.
template <int D>
void DemPart<D>::distribute_restored() {
  const parallel::Comm& comm = *comm_;
  contact_layout_builds_ = -1;
  const auto ranks = static_cast<std::size_t>(comm.size());
  const std::vector<Vec<D>> built(skin_.positions().begin(), skin_.positions().end());
  const std::vector<Real> weight(built.size(), 1.0);
  cuts_ = parallel::rcb_tree<D>(std::span<const Vec<D>>(built), weight, comm.size());
  std::vector<int> owner(built.size());
  std::vector<fields::Box<D>> box(ranks);
  for (std::size_t i = 0; i < built.size(); ++i) {
    owner[i] = cuts_.owner(built[i]);
    box[static_cast<std::size_t>(owner[i])].add(built[i]);
  }
  const Real reach2 = skin_.radius() * skin_.radius();  // as Halo::build
  const auto me = static_cast<std::size_t>(comm.rank());
  auto near = [&](std::size_t r, std::size_t i) {
    return !box[r].empty() && box[r].distance2(built[i]) <= reach2;
  };
  std::vector<std::uint8_t> keep(built.size()), is_ghost(built.size());
  for (std::size_t i = 0; i < built.size(); ++i) {
    const bool mine = owner[i] == comm.rank();
    is_ghost[i] = !mine && near(me, i);
    keep[i] = mine || is_ghost[i];
  }
  // The exchanges' lists in ascending id on both sides (before the sort, in old indices).
  std::vector<std::vector<std::pair<std::int64_t, Index>>> send(ranks), recv(ranks);
  for (std::size_t i = 0; i < built.size(); ++i) {
    const auto idx = static_cast<Index>(i);
    if (owner[i] == comm.rank()) {
      for (std::size_t r = 0; r < ranks; ++r)
        if (r != me && near(r, i)) send[r].emplace_back(id_[idx], idx);
    } else if (is_ghost[i]) {
      recv[static_cast<std::size_t>(owner[i])].emplace_back(id_[idx], idx);
    }
  }
  // Old index -> index among the kept grains.
  std::vector<Index> kept_at(built.size(), -1);
  std::vector<Vec<D>> local_built;
  Index k = 0;
  for (std::size_t i = 0; i < built.size(); ++i)
    if (keep[i]) {
      kept_at[i] = k++;
      local_built.push_back(built[i]);
    }
  ghost_.clear();
  for (std::size_t i = 0; i < built.size(); ++i)
    if (keep[i]) ghost_.push_back(is_ghost[i]);
  keep_grains(keep);
  auto lists = [&](std::vector<std::vector<std::pair<std::int64_t, Index>>>& from,
                   std::vector<std::vector<Index>>& to) {
    to.assign(ranks, {});
    for (std::size_t r = 0; r < ranks; ++r) {
      std::sort(from[r].begin(), from[r].end());
      for (const auto& [id, i] : from[r])
        to[r].push_back(kept_at[at(i)]);
    }
  };
  lists(send, halo_send_);
  lists(recv, halo_recv_);
  // The order of the build: its positions' cells, by id within a cell.
  const auto order = neighbors::cell_sort_order<D>(
      std::span<const Vec<D>>(local_built), skin_.radius(), std::span<const std::int64_t>(id_));
  f_.permute(order);
  permute_slots(order);
  reorder_halo(order);
  std::vector<Vec<D>> sorted(local_built.size());
  for (std::size_t q = 0; q < order.size(); ++q)
    sorted[q] = local_built[at(order[q])];
  skin_ = skin_.with_positions(std::move(sorted));
  clear_wall_slots();
  resize_bond_scratch();
  moved_sq_ = -1;
  if (skin_.listed()) build_lists();
}

// The walls' histories per grain, emptied for the new count (unpack_history fills them from the
// packed slots when the lists are built).
template <int D>
void DemPart<D>::clear_wall_slots() {
  const std::size_t wall_slots = static_cast<std::size_t>(f_.size()) * wall_planes_.size();
  wall_xi_.assign(wall_slots, Vec<D>::Zero());
  if (!wall_roll_.empty()) wall_roll_.assign(wall_slots, angular_zero<D>());
  wall_live_.assign(static_cast<std::size_t>(f_.size()), 0);
  if (!moving_.empty()) wall_load_.assign(wall_slots, WallLoad{});
}

template <int D>
void DemPart<D>::keep_grains(std::span<const std::uint8_t> keep) {
  constexpr auto slots = static_cast<std::size_t>(kMaxContacts);
  auto compact = [&](auto& v) {
    if (v.empty()) return;
    std::size_t k = 0;
    for (std::size_t i = 0; i < keep.size(); ++i) {
      if (!keep[i]) continue;
      if (k != i)
        for (std::size_t s = 0; s < slots; ++s)
          v[k * slots + s] = v[i * slots + s];
      ++k;
    }
    v.resize(k * slots);
  };
  compact(partner_);
  compact(xi_);
  compact(roll_);
  compact(bond_partner_);
  compact(bond_);
  f_.compact(keep);
}

// The next pair pass's bond slots (written in full by it), for the current count: after the
// grains were spread, moved or removed, or loaded.
template <int D>
void DemPart<D>::resize_bond_scratch() {
  if (!bonded_) return;
  bond_partner_new_.assign(bond_partner_.size(), kNoContact);
  bond_new_.assign(bond_.size(), ParallelBondState<D>{});
}

// A message: the grains' count, their fields (every field) and their packed slots (those of
// `slots_of`: partner_, xi_, roll_ at a rebuild; histories packed for the purpose otherwise),
// and with bonds their bond slots (partner ids and states).
template <int D>
void DemPart<D>::pack_grains(std::span<const Index> which, std::vector<std::byte>& out,
                             const PackedSlots& slots_of) const {
  constexpr auto slots = static_cast<std::size_t>(kMaxContacts);
  const bool rolling = rolling_.friction > 0;
  const auto count = static_cast<std::int64_t>(which.size());
  put(out, &count, sizeof count);
  f_.pack(which, fields::kEveryField, out);
  for (const Index i : which) {
    const std::size_t base = at(i) * slots;
    put(out, slots_of.partner.data() + base, slots * sizeof(std::int64_t));
    for (std::size_t s = 0; s < slots; ++s)
      put(out, reals<D>(slots_of.xi[base + s]), D * sizeof(Real));
    if (rolling)
      for (std::size_t s = 0; s < slots; ++s)
        put(out, angular_reals<D>(slots_of.roll[base + s]), kAngular<D> * sizeof(Real));
    if (bonded_) {
      put(out, slots_of.bond_partner.data() + base, slots * sizeof(std::int64_t));
      put(out, slots_of.bond.data() + base, slots * sizeof(ParallelBondState<D>));
    }
  }
}

// Appends the grains of a message of pack_grains to `set` and their slots to the others.
template <int D>
void DemPart<D>::unpack_grains(std::span<const std::byte> in, fields::FieldSet<D>& set,
                               const SlotsInto& into) const {
  constexpr auto slots = static_cast<std::size_t>(kMaxContacts);
  const bool rolling = rolling_.friction > 0;
  Reader r{in};
  std::int64_t count = 0;
  r.get(&count, sizeof count);
  const auto n = static_cast<std::size_t>(count);
  set.unpack_append(r.take(n * set.packed_bytes(fields::kEveryField)), fields::kEveryField);
  for (std::size_t q = 0; q < n; ++q) {
    const std::size_t base = into.partner.size();
    into.partner.resize(base + slots);
    into.xi.resize(base + slots);
    r.get(into.partner.data() + base, slots * sizeof(std::int64_t));
    for (std::size_t s = 0; s < slots; ++s)
      r.get(reals<D>(into.xi[base + s]), D * sizeof(Real));
    if (rolling) {
      into.roll.resize(base + slots);
      for (std::size_t s = 0; s < slots; ++s)
        r.get(angular_reals<D>(into.roll[base + s]), kAngular<D> * sizeof(Real));
    }
    if (bonded_) {
      into.bond_partner.resize(base + slots);
      into.bond.resize(base + slots);
      r.get(into.bond_partner.data() + base, slots * sizeof(std::int64_t));
      r.get(into.bond.data() + base, slots * sizeof(ParallelBondState<D>));
    }
  }
  if (r.at != in.size()) throw std::logic_error("dem ranks: a message is too long");
}

template <int D>
void DemPart<D>::redistribute(Real reach) {
  const parallel::Comm& comm = *comm_;
  const auto ranks = static_cast<std::size_t>(comm.size());
  auto pack = [&](std::span<const Index> which, std::vector<std::byte>& out) {
    pack_grains(which, out, {partner_, xi_, roll_, bond_partner_, bond_});
  };
  auto unpack = [&](std::span<const std::byte> in) {
    unpack_grains(in, f_, {partner_, xi_, roll_, bond_partner_, bond_});
  };

  // 1. The ghosts go.
  std::vector<std::uint8_t> keep(static_cast<std::size_t>(f_.size()));
  for (Index i = 0; i < f_.size(); ++i)
    keep[at(i)] = !ghost(i);
  keep_grains(keep);

  // 2. Grains now in another rank's box move there; the cuts are made again first if the ranks'
  // grain counts, or their measured times (domain.balance), part (fields/balance.hpp).
  const std::vector<Real> weight(static_cast<std::size_t>(f_.size()), 1.0);
  if (auto cuts =
          fields::rebalanced_cuts<D>(comm, std::span<const Vec<D>>(x_.data(), x_.size()),
                                     std::span<const Real>(weight), &load_ratio_, &busy_, &cuts_)) {
    cuts_ = std::move(*cuts);
    ++rebalances_;
  }
  std::vector<std::vector<Index>> leaving(ranks);
  keep.assign(static_cast<std::size_t>(f_.size()), 1);
  for (Index i = 0; i < f_.size(); ++i) {
    const int owner = cuts_.owner(x_[i]);
    if (owner == comm.rank()) continue;
    leaving[static_cast<std::size_t>(owner)].push_back(i);
    keep[at(i)] = 0;
  }
  std::vector<std::vector<std::byte>> send(ranks);
  for (std::size_t r = 0; r < ranks; ++r)
    if (static_cast<int>(r) != comm.rank()) pack(leaving[r], send[r]);
  auto received = comm.all_to_all(send);
  keep_grains(keep);
  const Index staying = f_.size();
  for (std::size_t r = 0; r < ranks; ++r)
    if (static_cast<int>(r) != comm.rank()) unpack(received[r]);
  const Index owned = f_.size();
  arrivals_ += owned - staying;

  // 3. The ghosts: the other ranks' grains within reach of this rank's.
  fields::Halo<D> halo;
  halo.build(comm, std::span<const Vec<D>>(x_), reach);
  halo_send_ = halo.send_lists();
  for (std::size_t r = 0; r < ranks; ++r) {
    send[r].clear();
    if (static_cast<int>(r) != comm.rank()) pack(halo_send_[r], send[r]);
  }
  received = comm.all_to_all(send);
  halo_recv_.assign(ranks, {});
  for (std::size_t r = 0; r < ranks; ++r) {
    if (static_cast<int>(r) == comm.rank()) continue;
    const Index first = f_.size();
    unpack(received[r]);
    for (Index i = first; i < f_.size(); ++i)
      halo_recv_[r].push_back(i);
  }
  ghost_.assign(static_cast<std::size_t>(f_.size()), 1);
  std::fill_n(ghost_.begin(), at(owned), std::uint8_t{0});
  clear_wall_slots();
  resize_bond_scratch();
}

// After the canonical sort (order[k]: the grain now at k): the ghost flags and the halo's
// lists follow the grains.
template <int D>
void DemPart<D>::reorder_halo(std::span<const Index> order) {
  std::vector<Index> to(order.size());
  std::vector<std::uint8_t> ghost(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    to[at(order[k])] = static_cast<Index>(k);
    ghost[k] = ghost_[at(order[k])];
  }
  ghost_.swap(ghost);
  for (auto* lists : {&halo_send_, &halo_recv_})
    for (auto& list : *lists)
      for (Index& i : list)
        i = to[at(i)];
}

// The ghosts' positions, velocities and angular velocities, from their owners.
template <int D>
void DemPart<D>::refresh_ghosts() {
  const parallel::Comm& comm = *comm_;
  const auto ranks = static_cast<std::size_t>(comm.size());
  constexpr std::size_t per = (2 * D + kAngular<D>)*sizeof(Real);
  std::vector<std::vector<std::byte>> send(ranks);
  for (std::size_t r = 0; r < ranks; ++r) {
    send[r].reserve(halo_send_[r].size() * per);
    for (const Index i : halo_send_[r]) {
      put(send[r], reals<D>(x_[i]), D * sizeof(Real));
      put(send[r], reals<D>(v_[i]), D * sizeof(Real));
      put(send[r], angular_reals<D>(w_[i]), kAngular<D> * sizeof(Real));
    }
  }
  const auto received = comm.all_to_all(send);
  for (std::size_t r = 0; r < ranks; ++r) {
    if (static_cast<int>(r) == comm.rank()) continue;
    if (received[r].size() != halo_recv_[r].size() * per)
      throw std::logic_error("dem ranks: the ghosts' motion does not match the halo");
    Reader in{received[r]};
    for (const Index i : halo_recv_[r]) {
      in.get(reals<D>(x_[i]), D * sizeof(Real));
      in.get(reals<D>(v_[i]), D * sizeof(Real));
      in.get(angular_reals<D>(w_[i]), kAngular<D> * sizeof(Real));
    }
  }
}

template <int D>
Index DemPart<D>::count() const {
  if (!comm_) return f_.size();
  Index owned = 0;
  for (Index i = 0; i < f_.size(); ++i)
    owned += !ghost(i);
  return static_cast<Index>(comm_->sum(static_cast<std::int64_t>(owned)));
}

// On ranks: the fault of smallest grain id over the ranks, its message from the rank that
// found it (a ghost's fault is its owner's too, so the same grain is named).
template <int D>
std::optional<parts::Fault> DemPart<D>::check() const {
  std::optional<parts::Fault> mine = local_check();
  if (!comm_) return mine;
  return parts::first_fault(*comm_, mine);
}

template <int D>
std::optional<parts::GatheredPoints<D>> DemPart<D>::gathered_points() const {
  if (!comm_) return std::nullopt;
  return parts::gather_points<D>(*comm_, std::span<const std::int64_t>(id_),
                                 std::span<const Vec<D>>(x_), point_fields(),
                                 [&](Index i) { return !ghost(i); });
}

template <int D>
std::optional<parts::GatheredPoints<D>> DemPart<D>::own_piece() const {
  if (!comm_) return std::nullopt;
  return parts::piece_points<D>(std::span<const Vec<D>>(x_), point_fields(),
                                [&](Index i) { return !ghost(i); });
}

template <int D>
std::optional<parts::OwnNumbers> DemPart<D>::own_numbers() const {
  if (!comm_) return std::nullopt;
  parts::OwnNumbers n;
  n.point =
      parts::own_numbers_of(std::span<const std::int64_t>(id_), [&](Index i) { return ghost(i); });
  return n;
}

// The grains each rank owns (fewest, most) and the ghosts it holds (mean, most), the bytes of one
// refresh of the ghosts' motion summed over the ranks, how often the cuts were made again, and
// how many grains moved to another rank (arrivals summed over the ranks).
template <int D>
std::vector<parts::Diagnostic> DemPart<D>::rank_figures() const {
  if (!comm_) return {};
  Index owned = 0;
  for (Index i = 0; i < f_.size(); ++i)
    owned += !ghost(i);
  const Index ghosts = f_.size() - owned;
  const auto ranks = static_cast<Real>(comm_->size());
  const auto all_ghosts = static_cast<Real>(comm_->sum(static_cast<std::int64_t>(ghosts)));
  constexpr Real kRefreshBytes = (2 * D + kAngular<D>)*sizeof(Real);
  return {{"owned_min", comm_->min(static_cast<Real>(owned))},
          {"owned_max", comm_->max(static_cast<Real>(owned))},
          {"ghosts_mean", all_ghosts / ranks},
          {"ghosts_max", comm_->max(static_cast<Real>(ghosts))},
          {"ghost_refresh_bytes_per_step", all_ghosts * kRefreshBytes},
          {"rebalances", static_cast<Real>(rebalances_)},
          {"load_ratio", load_ratio_},
          {"migrations", static_cast<Real>(comm_->sum(static_cast<std::int64_t>(arrivals_)))}};
}

// A checkpoint on ranks: every rank sends its grains (fields, packed histories, and where each
// was when the lists were built) to the root, which writes the whole part in the order one rank
// would hold it, the cell order of the positions at that build (cell_sort_order is canonical):
// the file is that of a run on one rank, byte for byte, and resumes there.
template <int D>
void DemPart<D>::save_gathered(parts::StateWriter& w) const {
  const parallel::Comm& comm = *comm_;
  std::vector<std::int64_t> partner;
  std::vector<Vec<D>> xi;
  std::vector<AngularVec<D>> roll;
  if (!packed_) pack_history(partner, xi, roll);
  const PackedSlots slots_of = packed_ ? PackedSlots{partner_, xi_, roll_, bond_partner_, bond_}
                                       : PackedSlots{partner, xi, roll, bond_partner_, bond_};
  const auto [owned, built] =
      parts::owned_at_build<D>(f_.size(), skin_.positions(), [&](Index i) { return ghost(i); });
  std::vector<std::byte> mine;
  pack_grains(owned, mine, slots_of);
  std::vector<std::int64_t> bytes;
  const std::vector<std::byte> all = comm.gather(mine, &bytes);
  const std::vector<Real> all_built = parallel::gather(comm, std::span<const Real>(built));
  if (!comm.root()) return;  // the root writes
  fields::FieldSet<D> whole = f_;
  whole.resize(0);
  std::vector<std::int64_t> w_partner, w_bond_partner;
  std::vector<Vec<D>> w_xi;
  std::vector<AngularVec<D>> w_roll;
  std::vector<ParallelBondState<D>> w_bond;
  std::size_t from = 0;
  for (const std::int64_t b : bytes) {
    unpack_grains(std::span<const std::byte>(all).subspan(from, static_cast<std::size_t>(b)), whole,
                  {w_partner, w_xi, w_roll, w_bond_partner, w_bond});
    from += static_cast<std::size_t>(b);
  }
  // The order of one rank: cells of the positions at the build, by id within a cell.
  auto [order, w_built] =  // w_built: in that order
      parts::order_of_one_rank<D>(whole, std::span<const Real>(all_built), skin_.radius());
  whole.permute(order);
  constexpr auto slots = static_cast<std::size_t>(kMaxContacts);
  auto permute = [&](auto& v, std::size_t per) {
    if (v.empty()) return;
    auto copy = v;
    for (std::size_t k = 0; k < order.size(); ++k)
      for (std::size_t s = 0; s < per; ++s)
        v[k * per + s] = copy[at(order[k]) * per + s];
  };
  permute(w_partner, slots);
  permute(w_xi, slots);
  permute(w_roll, slots);
  permute(w_bond_partner, slots);
  permute(w_bond, slots);
  w.tag("dem");
  whole.save(w);
  w.vector(w_partner);
  w.vector(w_xi);
  w.vector(w_roll);
  const neighbors::VerletSkin<D> skin = skin_.with_positions(std::move(w_built));
  // bond_lost_ is a grain index, the count when none was lost (a lost one ends the run): the
  // whole part's count, as one rank holds it.
  auto* self = const_cast<DemPart<D>*>(this);  // set for the write, then back
  const Index lost = bond_lost_;
  self->bond_lost_ = whole.size();
  archive_bonds_and_ledgers(w, *this, skin, std::as_const(w_bond_partner), std::as_const(w_bond));
  self->bond_lost_ = lost;
}

// The contacts with other parts on ranks see the whole bed in the order one rank holds it: the
// cell order of the positions at the last build of the lists (contact/spread_coupling.hpp).
template <int D>
const parts::WholeLayout* DemPart<D>::contact_layout() const {
  if (!comm_) return nullptr;
  // The same until the grains are sorted and spread again, at the next build of the lists.
  if (contact_layout_builds_ == skin_.builds()) return &contact_layout_;
  contact_layout_ =
      parts::particle_layout<D>(*comm_, std::span<const std::int64_t>(id_), skin_.positions(),
                                skin_.radius(), [&](Index i) { return !ghost(i); });
  contact_layout_builds_ = skin_.builds();
  return &contact_layout_;
}

#define CRATER_DEM_RANKS(D)                                                                 \
  template const parts::WholeLayout* DemPart<D>::contact_layout() const;                    \
  template void DemPart<D>::distribute(const parallel::Comm&);                              \
  template void DemPart<D>::keep_grains(std::span<const std::uint8_t>);                     \
  template void DemPart<D>::distribute_restored();                                          \
  template void DemPart<D>::redistribute(Real);                                             \
  template void DemPart<D>::reorder_halo(std::span<const Index>);                           \
  template void DemPart<D>::refresh_ghosts();                                               \
  template void DemPart<D>::save_gathered(parts::StateWriter&) const;                       \
  template void DemPart<D>::pack_grains(std::span<const Index>, std::vector<std::byte>&,    \
                                        const PackedSlots&) const;                          \
  template void DemPart<D>::clear_wall_slots();                                             \
  template void DemPart<D>::unpack_grains(std::span<const std::byte>, fields::FieldSet<D>&, \
                                          const SlotsInto&) const;                          \
  template void DemPart<D>::resize_bond_scratch();                                          \
  template Index DemPart<D>::count() const;                                                 \
  template std::optional<parts::Fault> DemPart<D>::check() const;                           \
  template std::optional<parts::GatheredPoints<D>> DemPart<D>::gathered_points() const;     \
  template std::optional<parts::GatheredPoints<D>> DemPart<D>::own_piece() const;           \
  template std::optional<parts::OwnNumbers> DemPart<D>::own_numbers() const;                \
  template std::vector<parts::Diagnostic> DemPart<D>::rank_figures() const;
CRATER_DEM_RANKS(2)
CRATER_DEM_RANKS(3)
#undef CRATER_DEM_RANKS

}  // namespace crater::dem::detail
