// Entities between ranks (issue 29, docs/distributed.md, "Decomposition, halos, migration"),
// over a part's FieldSet. Here rather than in parallel/, which fields/ includes:
// - migrate() moves the entities another rank now owns to it, every field with them, and leaves
//   each rank's entities in ascending order of their global id;
// - Halo copies to each rank the other ranks' entities within a reach of its box (the ghosts),
//   the fields of a role (kHalo) only, also in ascending order of id.
// Both orders depend only on which entities a rank holds, not on the rank count nor on the
// order in which they arrived: what a rank computes from them can then be the same for any
// decomposition.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "fields/field_set.hpp"
#include "parallel/comm.hpp"

namespace crater::fields {

/// What one exchange moved, seen from this rank.
struct Traffic {
  Index sent = 0;      // entities (copies, for a halo) sent to other ranks
  Index received = 0;  // entities received from other ranks
  std::int64_t bytes_sent = 0;
};

/// Orders the entities of `set` by ascending `id` (a field of the set; ids must be unique).
template <int D>
void sort_by_id(FieldSet<D>& set, const std::vector<std::int64_t>& id) {
  std::vector<Index> order(static_cast<std::size_t>(set.size()));
  std::iota(order.begin(), order.end(), Index{0});
  std::sort(order.begin(), order.end(), [&](Index a, Index b) {
    return id[static_cast<std::size_t>(a)] < id[static_cast<std::size_t>(b)];
  });
  for (std::size_t k = 1; k < order.size(); ++k)
    if (id[static_cast<std::size_t>(order[k])] == id[static_cast<std::size_t>(order[k - 1])])
      throw std::logic_error("sort_by_id: id " +
                             std::to_string(id[static_cast<std::size_t>(order[k])]) +
                             " appears twice");
  if (!std::is_sorted(order.begin(), order.end())) set.permute(order);
}

/// Moves every entity i of `set` whose owner[i] is another rank to that rank, with all its
/// fields (a move: it leaves this rank), and orders each rank's entities by ascending `id` (a
/// field of the set). Collective: every rank calls it.
template <int D>
Traffic migrate(const parallel::Comm& comm, FieldSet<D>& set, std::span<const int> owner,
                const std::vector<std::int64_t>& id) {
  if (static_cast<Index>(owner.size()) != set.size())
    throw std::logic_error("migrate: one owner per entity expected");
  const auto ranks = static_cast<std::size_t>(comm.size());
  std::vector<std::vector<Index>> leaving(ranks);
  std::vector<std::uint8_t> keep(owner.size(), 1);
  for (std::size_t i = 0; i < owner.size(); ++i) {
    if (owner[i] < 0 || owner[i] >= comm.size())
      throw std::logic_error("migrate: owner " + std::to_string(owner[i]) + " is no rank");
    if (owner[i] != comm.rank()) {
      leaving[static_cast<std::size_t>(owner[i])].push_back(static_cast<Index>(i));
      keep[i] = 0;
    }
  }
  Traffic t;
  std::vector<std::vector<std::byte>> send(ranks);
  for (std::size_t r = 0; r < ranks; ++r) {
    set.pack(leaving[r], kEveryField, send[r]);
    t.sent += static_cast<Index>(leaving[r].size());
    t.bytes_sent += static_cast<std::int64_t>(send[r].size());
  }
  const auto received = comm.all_to_all(send);
  set.compact(keep);
  for (std::size_t r = 0; r < ranks; ++r)
    if (static_cast<int>(r) != comm.rank())
      t.received += set.unpack_append(received[r], kEveryField);
  sort_by_id(set, id);
  return t;
}

/// The axis-aligned box of a set of points; empty (lo > hi) for none.
template <int D>
struct Box {
  Vec<D> lo = Vec<D>::Constant(std::numeric_limits<Real>::infinity());
  Vec<D> hi = Vec<D>::Constant(-std::numeric_limits<Real>::infinity());

  bool empty() const { return (lo.array() > hi.array()).any(); }
  void add(const Vec<D>& x) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  /// Squared distance from x to the box (0 inside).
  Real distance2(const Vec<D>& x) const {
    const Vec<D> out = (lo - x).cwiseMax(x - hi).cwiseMax(Vec<D>::Zero());
    return out.squaredNorm();
  }
};

/// Which owned entities each other rank needs, and their copies sent there as ghosts.
template <int D>
class Halo {
 public:
  /// Finds, for every other rank, this rank's entities within `reach` of that rank's box (the
  /// box of the positions it owns). Collective. The lists hold for as long as the entities do
  /// not move further than the reach leaves room for (rebuilt with the neighbour lists).
  void build(const parallel::Comm& comm, std::span<const Vec<D>> x, Real reach) {
    if (!(reach >= 0)) throw std::logic_error("Halo::build: the reach must be >= 0");
    Box<D> mine;
    for (const auto& p : x)
      mine.add(p);
    std::array<Real, 2 * D> packed;  // Eigen's vectors are not trivially copyable: numbers
    for (int a = 0; a < D; ++a) {
      packed[static_cast<std::size_t>(a)] = mine.lo[a];
      packed[static_cast<std::size_t>(D + a)] = mine.hi[a];
    }
    const auto all =
        parallel::all_gather(comm, std::span<const std::array<Real, 2 * D>>(&packed, 1));
    std::vector<Box<D>> boxes(all.size());
    for (std::size_t r = 0; r < all.size(); ++r)
      for (int a = 0; a < D; ++a) {
        boxes[r].lo[a] = all[r][static_cast<std::size_t>(a)];
        boxes[r].hi[a] = all[r][static_cast<std::size_t>(D + a)];
      }
    send_.assign(boxes.size(), {});
    const Real reach2 = reach * reach;
    for (std::size_t r = 0; r < boxes.size(); ++r) {
      if (static_cast<int>(r) == comm.rank() || boxes[r].empty()) continue;
      for (std::size_t i = 0; i < x.size(); ++i)
        if (boxes[r].distance2(x[i]) <= reach2) send_[r].push_back(static_cast<Index>(i));
    }
  }

  /// ghosts := copies of the other ranks' entities within the reach of this rank's box, with the
  /// fields having `roles` (the others zero), in ascending order of `ghost_id` (the ghosts' id
  /// field, which must have `roles`). `ghosts` has the fields of `owned`. Collective.
  Traffic exchange(const parallel::Comm& comm, const FieldSet<D>& owned, unsigned roles,
                   FieldSet<D>& ghosts, const std::vector<std::int64_t>& ghost_id) const {
    if (static_cast<int>(send_.size()) != comm.size())
      throw std::logic_error("Halo::exchange before build");
    Traffic t;
    std::vector<std::vector<std::byte>> send(send_.size());
    for (std::size_t r = 0; r < send_.size(); ++r) {
      if (!send_[r].empty() && send_[r].back() >= owned.size())  // the lists ascend
        throw std::logic_error("Halo::exchange: the set has shrunk");
      owned.pack(send_[r], roles, send[r]);
      t.sent += static_cast<Index>(send_[r].size());
      t.bytes_sent += static_cast<std::int64_t>(send[r].size());
    }
    const auto received = comm.all_to_all(send);
    ghosts.resize(0);
    for (std::size_t r = 0; r < received.size(); ++r)
      if (static_cast<int>(r) != comm.rank())
        t.received += ghosts.unpack_append(received[r], roles);
    sort_by_id(ghosts, ghost_id);
    return t;
  }

  /// Per rank, the indices of this rank's entities it receives, ascending.
  const std::vector<std::vector<Index>>& send_lists() const { return send_; }

 private:
  std::vector<std::vector<Index>> send_;
};

}  // namespace crater::fields
