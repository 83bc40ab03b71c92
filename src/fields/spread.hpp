// A part's entities spread over ranks, with ghosts in the same arrays (issue 29,
// docs/distributed.md, "The SPH part on ranks"). What a part needs to run on several ranks when
// an entity's state is its fields alone (the SPH part; the DEM part, whose grains also carry
// their contact histories, has its own, src/dem/dem_ranks.cpp):
// - the cuts, a recursive coordinate bisection of the whole set at the start (every rank holds
//   all of it then), by count; made again at a rebuild when one rank carries more than a
//   tolerance above the mean of a weight the part gives or of its measured time (balance.hpp,
//   rebalanced_cuts);
// - at each rebuild of the part's lists: the ghosts go, the entities whose position lies in
//   another rank's box move there with every field, and each rank receives copies of the other
//   ranks' entities within a reach of its own (ghosts, every field), appended after its own;
// - between rebuilds, the ghosts' fields of a role refreshed from their owners.
// The part sorts owned entities and ghosts together in its canonical order (a cell order with ids
// breaking ties) and reports the permutation, so that every sum over an entity's neighbours runs
// over the same neighbours in the same order as on one rank.
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/types.hpp"
#include "fields/balance.hpp"
#include "fields/exchange.hpp"
#include "fields/field_set.hpp"
#include "parallel/comm.hpp"
#include "parallel/rcb.hpp"

namespace crater::fields {

/// New cuts when the ranks' loads part: each rank's entities `x` with their model weights `w`
/// (its own entities only). The load of a rank is its summed weight, or, `busy` by time
/// (balance.hpp), its measured time since the window began. When the busiest rank exceeds the
/// mean by more than kRebalanceTolerance, the cuts of an RCB of every rank's entities
/// (all-gathered in rank order), each weighted by its model weight, times, by time, its rank's
/// seconds per unit of model weight; else nothing. By
/// time, a window shorter than kTimeWindowSteps decides nothing, and a longer one is started again
/// after deciding. Every rank decides alike from the same gathered sums. Collective. `load_ratio`,
/// if given: the heaviest rank's load over the mean (1 for none; unchanged when nothing was
/// decided).
template <int D>
std::optional<parallel::RcbTree<D>> rebalanced_cuts(const parallel::Comm& comm,
                                                    std::span<const Vec<D>> x,
                                                    std::span<const Real> w,
                                                    Real* load_ratio = nullptr,
                                                    BusyClock* busy = nullptr,
                                                    const parallel::RcbTree<D>* before = nullptr) {
  const bool timed = busy && busy->by_time;
  Real mine[2] = {0, timed ? static_cast<Real>(busy->busy_s) : Real(0)};
  for (const Real v : w)
    mine[0] += v;
  // By time, the window's length decides alike on every rank (the steps are every rank's).
  if (timed && busy->steps < kTimeWindowSteps) return std::nullopt;
  const std::vector<Real> load = parallel::all_gather(comm, std::span<const Real>(mine, 2));
  const std::size_t ranks = load.size() / 2, at = timed ? 1 : 0;
  Real sum = 0, most = 0, least = load[at];
  for (std::size_t r = 0; r < ranks; ++r) {
    sum += load[2 * r + at];
    most = std::max(most, load[2 * r + at]);
    least = std::min(least, load[2 * r + at]);
  }
  if (timed) busy->restart();
  const Real mean = sum / static_cast<Real>(ranks);
  // A rank that measured no time (a clock's resolution) leaves the cuts to the next window.
  if (timed && !(least > 0)) return std::nullopt;
  if (load_ratio) *load_ratio = mean > 0 ? most / mean : Real(1);
  if (!(most > (1 + kRebalanceTolerance) * mean)) return std::nullopt;
  // By time: this rank's seconds per unit of model weight scales its entities' weights.
  const Real scale = timed && mine[0] > 0 ? mine[1] / mine[0] : Real(1);
  std::vector<Real> coords(x.size() * D), scaled(w.begin(), w.end());
  for (Real& v : scaled)
    v *= scale;
  for (std::size_t i = 0; i < x.size(); ++i)
    for (int d = 0; d < D; ++d)
      coords[i * D + static_cast<std::size_t>(d)] = x[i][d];
  const std::vector<Real> all = parallel::all_gather(comm, std::span<const Real>(coords));
  const std::vector<Real> all_w = parallel::all_gather(comm, std::span<const Real>(scaled));
  std::vector<Vec<D>> all_x(all_w.size());
  for (std::size_t i = 0; i < all_x.size(); ++i)
    for (int d = 0; d < D; ++d)
      all_x[i][d] = all[i * D + static_cast<std::size_t>(d)];
  return parallel::rcb_tree<D>(std::span<const Vec<D>>(all_x), std::span<const Real>(all_w),
                               comm.size(), before);
}

/// After a compaction of a spread part's local entities (keep[i] != 0: entity i is kept; the kept
/// ones keep their order): the ghost flags and the exchange lists (local indices, per rank)
/// follow the kept entities. A dropped entity leaves the lists, on both sides of an exchange when
/// its owner and the ranks that hold it as a ghost drop it alike.
inline void compact_exchange(std::span<const std::uint8_t> keep, std::vector<std::uint8_t>& ghost,
                             std::vector<std::vector<Index>>& send,
                             std::vector<std::vector<Index>>& recv) {
  std::vector<Index> to(keep.size(), -1);
  std::vector<std::uint8_t> kept_ghost;
  for (std::size_t i = 0; i < keep.size(); ++i) {
    if (!keep[i]) continue;
    to[i] = static_cast<Index>(kept_ghost.size());
    kept_ghost.push_back(i < ghost.size() ? ghost[i] : std::uint8_t{0});
  }
  ghost.swap(kept_ghost);
  for (auto* lists : {&send, &recv})
    for (auto& list : *lists) {
      std::vector<Index> kept;
      for (const Index i : list)
        if (to[static_cast<std::size_t>(i)] >= 0) kept.push_back(to[static_cast<std::size_t>(i)]);
      list.swap(kept);
    }
}

template <int D>
class Spread {
 public:
  bool active() const { return comm_ != nullptr; }
  const parallel::Comm& comm() const { return *comm_; }
  /// Whether local entity i is a copy of another rank's (never on one rank).
  bool ghost(Index i) const { return !ghost_.empty() && ghost_[static_cast<std::size_t>(i)] != 0; }
  /// This rank's own entities (all of them on one rank).
  Index owned(Index local_count) const {
    return local_count - static_cast<Index>(std::count(ghost_.begin(), ghost_.end(), 1));
  }
  Index ghosts() const { return static_cast<Index>(std::count(ghost_.begin(), ghost_.end(), 1)); }
  /// How many times the cuts were made again (rebalanced_cuts).
  Index rebalances() const { return rebalances_; }
  /// The heaviest rank's load over the mean at the last rebuild (rebalanced_cuts; 1 before).
  Real load_ratio() const { return load_ratio_; }
  /// How many entities arrived at this rank from another owner at rebuilds (migrations).
  Index arrivals() const { return arrivals_; }
  /// The part's measured load for cuts by time (balance.hpp).
  BusyClock& busy() { return busy_; }

  /// Cuts the whole set (every rank holds all of it, in the same order) by RCB of the positions
  /// x (a field of `set`), every entity weighted 1, and keeps this rank's entities, in their
  /// order. The ghosts come with the first rebuild().
  void start(const parallel::Comm& comm, FieldSet<D>& set, const std::vector<Vec<D>>& x) {
    if (comm_) throw std::logic_error("Spread::start twice");
    comm_ = &comm;
    const std::vector<Real> weight(x.size(), 1.0);
    cuts_ = parallel::rcb_tree<D>(std::span<const Vec<D>>(x), weight, comm.size());
    std::vector<std::uint8_t> keep(x.size());
    for (std::size_t i = 0; i < x.size(); ++i)
      keep[i] = cuts_.owner(x[i]) == comm.rank();
    set.compact(keep);
    ghost_.assign(static_cast<std::size_t>(set.size()), 0);
    send_.assign(static_cast<std::size_t>(comm.size()), {});
    recv_.assign(static_cast<std::size_t>(comm.size()), {});
  }

  /// At a rebuild of the lists (every rank at once): the ghosts go; the cuts are made again if
  /// the ranks' loads part (rebalanced_cuts, by the entities' `weight`, one per local entity,
  /// the ghosts' ignored); the entities whose position x (a field of `set`) lies in another
  /// rank's box move there with every field; then each rank receives copies of the others'
  /// entities within `reach` of the box of its own, with every field, appended after its own in
  /// rank order. `id` is the set's id field.
  Traffic rebuild(FieldSet<D>& set, const std::vector<Vec<D>>& x,
                  const std::vector<std::int64_t>& id, Real reach, std::span<const Real> weight) {
    const parallel::Comm& comm = *comm_;
    const auto ranks = static_cast<std::size_t>(comm.size());
    std::vector<std::uint8_t> keep(ghost_.size());
    std::vector<Real> own_weight;
    for (std::size_t i = 0; i < keep.size(); ++i) {
      keep[i] = ghost_[i] == 0;
      if (keep[i]) own_weight.push_back(weight[i]);
    }
    set.compact(keep);
    if (auto cuts = rebalanced_cuts<D>(
            comm, std::span<const Vec<D>>(x.data(), static_cast<std::size_t>(set.size())),
            own_weight, &load_ratio_, &busy_, &cuts_)) {
      cuts_ = std::move(*cuts);
      ++rebalances_;
    }
    std::vector<int> owner(static_cast<std::size_t>(set.size()));
    for (std::size_t i = 0; i < owner.size(); ++i)
      owner[i] = cuts_.owner(x[i]);
    Traffic moved = migrate(comm, set, std::span<const int>(owner), id);
    arrivals_ += moved.received;
    const Index owned = set.size();

    Halo<D> halo;
    halo.build(comm, std::span<const Vec<D>>(x.data(), static_cast<std::size_t>(owned)), reach);
    send_ = halo.send_lists();
    std::vector<std::vector<std::byte>> send(ranks);
    for (std::size_t r = 0; r < ranks; ++r)
      set.pack(send_[r], kEveryField, send[r]);
    const auto received = comm.all_to_all(send);
    recv_.assign(ranks, {});
    for (std::size_t r = 0; r < ranks; ++r) {
      if (static_cast<int>(r) == comm.rank()) continue;
      const Index first = set.size();
      set.unpack_append(received[r], kEveryField);
      for (Index i = first; i < set.size(); ++i)
        recv_[r].push_back(i);
    }
    ghost_.assign(static_cast<std::size_t>(set.size()), 1);
    std::fill_n(ghost_.begin(), static_cast<std::size_t>(owned), std::uint8_t{0});
    moved.received += set.size() - owned;
    return moved;
  }

  /// After set.permute(order) (order[k]: the entity now at k): the flags and the exchange lists
  /// follow the entities.
  void permuted(std::span<const Index> order) {
    if (!comm_) return;
    std::vector<Index> to(order.size());
    std::vector<std::uint8_t> ghost(order.size());
    for (std::size_t k = 0; k < order.size(); ++k) {
      to[static_cast<std::size_t>(order[k])] = static_cast<Index>(k);
      ghost[k] = ghost_[static_cast<std::size_t>(order[k])];
    }
    ghost_.swap(ghost);
    for (auto* lists : {&send_, &recv_})
      for (auto& list : *lists)
        for (Index& i : list)
          i = to[static_cast<std::size_t>(i)];
  }

  /// After set.compact(keep) (keep: 1 for the entities kept): the flags and the exchange lists
  /// follow the kept entities; a dropped entity leaves the lists (on both sides of an exchange
  /// when its owner and the ranks holding it as a ghost drop it alike).
  void compacted(std::span<const std::uint8_t> keep) {
    if (comm_) compact_exchange(keep, ghost_, send_, recv_);
  }

  /// The ghosts' fields having any of `roles`, from their owners. Collective.
  void refresh(FieldSet<D>& set, unsigned roles) const {
    const parallel::Comm& comm = *comm_;
    const auto ranks = static_cast<std::size_t>(comm.size());
    std::vector<std::vector<std::byte>> send(ranks);
    for (std::size_t r = 0; r < ranks; ++r)
      set.pack(send_[r], roles, send[r]);
    const auto received = comm.all_to_all(send);
    for (std::size_t r = 0; r < ranks; ++r)
      if (static_cast<int>(r) != comm.rank()) set.unpack_into(recv_[r], received[r], roles);
  }

  /// A set restored whole from a checkpoint (every rank holds all of it, in the order of one
  /// rank), `built` each entity's position at the last build of the lists: the cuts, this rank's
  /// entities and its ghosts within `reach` are made from those positions, as a rebuild would
  /// have made them then, without a message. The set keeps its order (the kept entities are a
  /// subsequence of it); returns the kept entities' `built` positions.
  std::vector<Vec<D>> restore(const parallel::Comm& comm, FieldSet<D>& set,
                              std::span<const Vec<D>> built, const std::vector<std::int64_t>& id,
                              Real reach) {
    if (comm_) throw std::logic_error("Spread::restore after start");
    comm_ = &comm;
    const auto ranks = static_cast<std::size_t>(comm.size());
    const std::vector<Real> weight(built.size(), 1.0);
    cuts_ = parallel::rcb_tree<D>(built, weight, comm.size());
    std::vector<int> owner(built.size());
    std::vector<Box<D>> box(ranks);
    for (std::size_t i = 0; i < built.size(); ++i) {
      owner[i] = cuts_.owner(built[i]);
      box[static_cast<std::size_t>(owner[i])].add(built[i]);
    }
    const Real reach2 = reach * reach;  // as Halo::build
    const auto me = static_cast<std::size_t>(comm.rank());
    auto near = [&](std::size_t r, std::size_t i) {
      return !box[r].empty() && box[r].distance2(built[i]) <= reach2;
    };
    std::vector<std::uint8_t> keep(built.size());
    std::vector<Vec<D>> kept_built;
    ghost_.clear();
    // The exchanges' lists in ascending id on both sides.
    std::vector<std::vector<std::pair<std::int64_t, Index>>> send(ranks), recv(ranks);
    for (std::size_t i = 0; i < built.size(); ++i) {
      const bool mine = owner[i] == comm.rank();
      const bool is_ghost = !mine && near(me, i);
      if (!mine && !is_ghost) continue;
      keep[i] = 1;
      const auto k = static_cast<Index>(kept_built.size());
      kept_built.push_back(built[i]);
      ghost_.push_back(is_ghost);
      if (is_ghost) recv[static_cast<std::size_t>(owner[i])].emplace_back(id[i], k);
      if (mine)
        for (std::size_t r = 0; r < ranks; ++r)
          if (r != me && near(r, i)) send[r].emplace_back(id[i], k);
    }
    set.compact(keep);
    auto lists = [&](std::vector<std::vector<std::pair<std::int64_t, Index>>>& from,
                     std::vector<std::vector<Index>>& to) {
      to.assign(ranks, {});
      for (std::size_t r = 0; r < ranks; ++r) {
        std::sort(from[r].begin(), from[r].end());
        for (const auto& entry : from[r])
          to[r].push_back(entry.second);
      }
    };
    lists(send, send_);
    lists(recv, recv_);
    return kept_built;
  }

 private:
  const parallel::Comm* comm_ = nullptr;
  parallel::RcbTree<D> cuts_;
  std::vector<std::uint8_t> ghost_;              // per local entity
  std::vector<std::vector<Index>> send_, recv_;  // per rank: what goes there, what comes from it
  Index rebalances_ = 0;
  Real load_ratio_ = 1;
  Index arrivals_ = 0;
  BusyClock busy_;
};

}  // namespace crater::fields
