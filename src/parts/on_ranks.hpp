// What a part spread over ranks (Part::distribute, issue 29) reports as one: the first fault and
// the smallest stable step over all ranks, each named by the entity of smallest id among those
// that have it, with the words of the rank that holds that entity. The same on every rank, and
// the same as the part on one rank reports (ties go to the smallest id there too).
#pragma once

#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "fields/field_set.hpp"
#include "neighbors/cell_grid.hpp"
#include "parallel/comm.hpp"
#include "parts/part.hpp"

namespace crater::parts {

/// A value over the ranks with the entity it belongs to and words about it.
struct Ranked {
  Real value = 0;
  std::int64_t id = std::numeric_limits<std::int64_t>::max();  // none
  std::string text;
};

/// The smallest value over the ranks, on equal values the smallest id (then the lowest rank),
/// with its text. One all-gather. Collective.
inline Ranked smallest_over_ranks(const parallel::Comm& comm, const Ranked& mine) {
  if (comm.size() == 1) return mine;
  std::vector<std::byte> bytes(sizeof(Real) + sizeof(std::int64_t) + mine.text.size());
  std::memcpy(bytes.data(), &mine.value, sizeof(Real));
  std::memcpy(bytes.data() + sizeof(Real), &mine.id, sizeof(std::int64_t));
  if (!mine.text.empty())
    std::memcpy(bytes.data() + sizeof(Real) + sizeof(std::int64_t), mine.text.data(),
                mine.text.size());
  std::vector<std::int64_t> counts;
  const auto all = comm.all_gather(bytes, &counts);
  Ranked best;
  bool first = true;
  std::size_t at = 0;
  for (const std::int64_t b : counts) {
    Ranked r;
    std::memcpy(&r.value, all.data() + at, sizeof(Real));
    std::memcpy(&r.id, all.data() + at + sizeof(Real), sizeof(std::int64_t));
    const std::size_t head = sizeof(Real) + sizeof(std::int64_t);
    r.text.assign(reinterpret_cast<const char*>(all.data()) + at + head,
                  static_cast<std::size_t>(b) - head);
    if (first || r.value < best.value || (r.value == best.value && r.id < best.id)) best = r;
    first = false;
    at += static_cast<std::size_t>(b);
  }
  return best;
}

/// The fault of smallest entity id over the ranks, with the message of a rank that found it (a
/// ghost's fault is its owner's too: the same entity is named). Collective.
inline std::optional<Fault> first_fault(const parallel::Comm& comm,
                                        const std::optional<Fault>& mine) {
  Ranked r;
  r.value = 1;  // none
  if (mine) r = Ranked{0, mine->entity_id, mine->what};
  const Ranked first = smallest_over_ranks(comm, r);
  if (first.value > 0) return std::nullopt;
  return Fault{first.id, first.text};
}

/// The smallest step over the ranks (ties: the smallest entity id), with that rank's reason.
/// Collective.
inline StableStep smallest_step(const parallel::Comm& comm, const StableStep& mine) {
  Ranked r;
  r.value = mine.dt_s;
  r.text = mine.reason;
  if (mine.entity_id >= 0) r.id = mine.entity_id;
  const Ranked best = smallest_over_ranks(comm, r);
  StableStep s = mine;
  s.dt_s = best.value;
  s.entity_id = best.id == Ranked{}.id ? -1 : best.id;
  s.reason = best.text;
  return s;
}

/// This rank's own entities of [0, n) (not `ghost`) and their positions at the last build of the
/// lists (`at_build`), D numbers each: what a part sends the root for a checkpoint.
template <int D, class Ghost>
std::pair<std::vector<Index>, std::vector<Real>> owned_at_build(Index n,
                                                                std::span<const Vec<D>> at_build,
                                                                Ghost&& ghost) {
  std::vector<Index> owned;
  std::vector<Real> built;
  for (Index i = 0; i < n; ++i) {
    if (ghost(i)) continue;
    owned.push_back(i);
    for (int d = 0; d < D; ++d)
      built.push_back(at_build[static_cast<std::size_t>(i)][d]);
  }
  return {owned, built};
}

/// A part gathered whole on the root for a checkpoint: `built` holds D numbers per entity of
/// `whole` (its position at the last build of the lists, in the order of `whole`). Returns the
/// order one rank holds the part in, the cell order of those positions by `cell_m` with the ids
/// breaking ties (order[k]: the entity at k; cell_sort_order is canonical), and the positions
/// in that order.
template <int D>
std::pair<std::vector<Index>, std::vector<Vec<D>>> order_of_one_rank(
    const fields::FieldSet<D>& whole, std::span<const Real> built, Real cell_m) {
  std::vector<Vec<D>> at_build(static_cast<std::size_t>(whole.size()));
  for (std::size_t q = 0; q < at_build.size(); ++q)
    for (int d = 0; d < D; ++d)
      at_build[q][d] = built[q * D + static_cast<std::size_t>(d)];
  const std::vector<fields::FieldView> views = whole.views(fields::kEveryField);
  const fields::FieldView* id = fields::find_field(views, "id");
  const auto order = neighbors::cell_sort_order<D>(
      std::span<const Vec<D>>(at_build), cell_m,
      std::span<const std::int64_t>(id->integer_data, static_cast<std::size_t>(whole.size())));
  std::vector<Vec<D>> sorted(at_build.size());
  for (std::size_t q = 0; q < order.size(); ++q)
    sorted[q] = at_build[static_cast<std::size_t>(order[q])];
  return {order, sorted};
}

}  // namespace crater::parts
