// Where the entities of a part spread over ranks (Part::distribute, issue 29) sit in the whole
// part as one rank holds it, and per-entity values assembled whole in that order on every rank.
// The contacts between parts run on these whole views on every rank alike
// (contact/spread_coupling.hpp, docs/distributed.md "Contacts on ranks"): every sum they take
// then runs in the order of one rank, with its bits.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/index.hpp"
#include "core/types.hpp"
#include "neighbors/cell_grid.hpp"
#include "parallel/comm.hpp"

namespace crater::parts {

/// A spread part's entities (particles, or a mesh's nodes) against the whole part.
struct WholeLayout {
  Index whole_count = 0;
  /// This rank's own entities (local indices, ascending): what it sends.
  std::vector<Index> owned;
  /// Every rank's own entities, rank after rank as an all-gather gives them: their place in
  /// the whole part; owned_by_rank[r] of them are rank r's.
  std::vector<Index> slot_of_gathered;
  std::vector<Index> owned_by_rank;
  /// Each local entity's place in the whole part (ghosts too: their owner's entity).
  std::vector<Index> whole_of_local;
};

/// Several per-entity vectors of a spread part assembled whole in one all-gather: add() each
/// vector of local values (one per local entity), exchange(), then take() each in the order
/// added; every rank gets the same whole vectors. The values travel as their bytes (numbers, or
/// fixed-size Eigen vectors of them, as the exchanges of fields/ send them).
class WholeExchange {
 public:
  explicit WholeExchange(const WholeLayout& layout) : layout_(layout) {}

  template <class T>
  void add(const std::vector<T>& local) {
    const std::size_t at_byte = mine_.size();
    mine_.resize(at_byte + layout_.owned.size() * sizeof(T));
    for (std::size_t q = 0; q < layout_.owned.size(); ++q)
      std::memcpy(mine_.data() + at_byte + q * sizeof(T), &local[at(layout_.owned[q])], sizeof(T));
    sizes_.push_back(sizeof(T));
  }

  /// Collective.
  void exchange(const parallel::Comm& comm) {
    all_ = comm.all_gather(mine_);
    std::size_t per_entity = 0;
    for (const std::size_t s : sizes_)
      per_entity += s;
    std::size_t entities = 0;
    for (const Index n : layout_.owned_by_rank)
      entities += at(n);
    if (all_.size() != entities * per_entity || entities != layout_.slot_of_gathered.size())
      throw std::logic_error("WholeExchange: " + std::to_string(all_.size()) +
                             " bytes gathered for " + std::to_string(entities) + " entities");
  }

  /// The whole vector of the field-th add().
  template <class T>
  std::vector<T> take(std::size_t field) const {
    if (field >= sizes_.size() || sizes_[field] != sizeof(T))
      throw std::logic_error("WholeExchange: no such field");
    std::vector<T> whole(at(layout_.whole_count));
    std::size_t rank_base = 0, g = 0;  // the rank's bytes, its first entity
    for (const Index owned : layout_.owned_by_rank) {
      const std::size_t n = at(owned);
      std::size_t from = rank_base;
      for (std::size_t f = 0; f < field; ++f)
        from += n * sizes_[f];
      for (std::size_t q = 0; q < n; ++q)
        std::memcpy(static_cast<void*>(&whole[at(layout_.slot_of_gathered[g + q])]),
                    all_.data() + from + q * sizeof(T), sizeof(T));
      for (const std::size_t s : sizes_)
        rank_base += n * s;
      g += n;
    }
    return whole;
  }

 private:
  const WholeLayout& layout_;
  std::vector<std::size_t> sizes_;  // bytes per entity of each field
  std::vector<std::byte> mine_, all_;
};

/// The entries of `whole` at each local entity's place (the inverse of WholeExchange, ghosts
/// included); no communication.
template <class T>
std::vector<T> local_of_whole(const WholeLayout& layout, const std::vector<T>& whole) {
  std::vector<T> local(layout.whole_of_local.size());
  for (std::size_t i = 0; i < local.size(); ++i)
    local[i] = whole[at(layout.whole_of_local[i])];
  return local;
}

/// The layout of a spread particle part whose whole order is that of one rank: the cell order
/// of the positions at the last build of its lists (`at_build`, by `cell_m`), ids breaking ties
/// (neighbors::cell_sort_order is canonical; parts::order_of_one_rank for checkpoints).
/// `own(i)`: local entity i is this rank's (not a ghost). Collective.
template <int D, class Own>
WholeLayout particle_layout(const parallel::Comm& comm, std::span<const std::int64_t> id,
                            std::span<const Vec<D>> at_build, Real cell_m, Own&& own) {
  if (at_build.size() != id.size())
    throw std::logic_error("particle_layout: one position at the build per entity expected");
  WholeLayout l;
  std::vector<std::int64_t> my_id;
  std::vector<Vec<D>> my_built;
  for (std::size_t i = 0; i < id.size(); ++i) {
    if (!own(static_cast<Index>(i))) continue;
    l.owned.push_back(static_cast<Index>(i));
    my_id.push_back(id[i]);
    my_built.push_back(at_build[i]);
  }
  std::vector<std::int64_t> id_bytes;
  const std::vector<std::byte> id_all =
      comm.all_gather(std::as_bytes(std::span<const std::int64_t>(my_id)), &id_bytes);
  std::vector<std::int64_t> all_id(id_all.size() / sizeof(std::int64_t));
  if (!all_id.empty()) std::memcpy(all_id.data(), id_all.data(), id_all.size());
  for (const std::int64_t b : id_bytes)
    l.owned_by_rank.push_back(
        static_cast<Index>(b / static_cast<std::int64_t>(sizeof(std::int64_t))));
  std::vector<Real> my_coords;
  for (const Vec<D>& x : my_built)
    for (int d = 0; d < D; ++d)
      my_coords.push_back(x[d]);
  const std::vector<Real> coords = parallel::all_gather(comm, std::span<const Real>(my_coords));
  std::vector<Vec<D>> all_built(all_id.size());
  for (std::size_t g = 0; g < all_built.size(); ++g)
    for (int d = 0; d < D; ++d)
      all_built[g][d] = coords[g * D + static_cast<std::size_t>(d)];
  l.whole_count = static_cast<Index>(all_id.size());
  const std::vector<Index> order = neighbors::cell_sort_order<D>(
      std::span<const Vec<D>>(all_built), cell_m, std::span<const std::int64_t>(all_id));
  l.slot_of_gathered.assign(all_id.size(), 0);
  for (std::size_t k = 0; k < order.size(); ++k)
    l.slot_of_gathered[at(order[k])] = static_cast<Index>(k);
  // Local entities by id: every id is some rank's own entity exactly once.
  std::vector<std::pair<std::int64_t, Index>> slot_by_id(all_id.size());
  for (std::size_t g = 0; g < all_id.size(); ++g)
    slot_by_id[g] = {all_id[g], l.slot_of_gathered[g]};
  std::sort(slot_by_id.begin(), slot_by_id.end());
  l.whole_of_local.resize(id.size());
  for (std::size_t i = 0; i < id.size(); ++i) {
    const auto it = std::lower_bound(slot_by_id.begin(), slot_by_id.end(),
                                     std::pair<std::int64_t, Index>{id[i], Index{-1}});
    if (it == slot_by_id.end() || it->first != id[i])
      throw std::logic_error("particle_layout: entity " + std::to_string(id[i]) +
                             " is no rank's own");
    l.whole_of_local[i] = it->second;
  }
  return l;
}

}  // namespace crater::parts
