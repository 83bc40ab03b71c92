// The candidate lists of a pairing (which point of one set may touch which of the other), kept
// from step to step. A list built for the radius reach + margin holds every pair within the
// reach of later steps until the two sets together have moved by the margin (the Verlet list of
// neighbors/verlet_skin.hpp, across two sets). It is rebuilt when that happens, when the
// reach has grown past what the margin covers, or when the second set is renumbered (a surface
// eroded: its revision differs; a particle removed or the set re-sorted: its ids differ).
//
// The first set's rows are kept by id. When that set is renumbered (a contact zone's view on
// ranks holds other grains every step) or one of its points has moved by more than the margin
// left, only the rows of the points new to the set or moved too far are searched again, against
// the second set as it was at the build; the others keep their rows. A row holds every point
// of the second set within the reach while its own point's displacement since its search and
// the second set's since the build together stay within the margin.
//
// A kept list is a superset of the fresh one with each row ascending, as the fresh one's, so a
// search that filters its candidates by the fresh list's own test finds the same hits whether
// the list is kept or new (particle_face_hits applies the distance test itself; a particle
// pair must overlap, which is stricter). Hence a restart, which starts without a list, repeats
// the run bit for bit, and so does any history of the first set's renumbering.
#pragma once

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "core/types.hpp"
#include "neighbors/neighbor_list.hpp"
#include "parts/part.hpp"

namespace crater::contact {

/// How the entities of one set are numbered: by their ids (particles, which keep an id when
/// others leave or the set is re-sorted), or by a revision that changes whenever the set does
/// (a surface's faces). An empty `ids` and no revision: unknown, the list is never kept.
struct Numbering {
  std::span<const std::int64_t> ids;
  std::uint64_t revision = 0;
  bool known = false;
};

/// The numbering of a part's contact points: by their ids when the part keeps them.
template <int D>
Numbering numbering(const parts::ContactPoints<D>& p) {
  if (!p.id) return {};
  return {.ids = std::span<const std::int64_t>(*p.id), .known = true};
}

template <int D>
class CrossCandidates {
 public:
  /// The margin as a fraction of the reach. A quarter: a grain of a soil bed on a plate
  /// keeps its list for tens of steps (the build was 14 % of `paper-20cm`'s run when rebuilt
  /// every step), while the candidates per particle grow by (1.25)^D at most.
  static constexpr Real kMarginFraction = 0.25;

  /// The candidates b of every point a within `reach`, and more (see above): row i lists
  /// indices of b, ascending.
  const neighbors::NeighborList& find(std::span<const Vec<D>> a, const Numbering& number_a,
                                      std::span<const Vec<D>> b, const Numbering& number_b,
                                      Real reach);

  /// Lists built so far (for tests and the performance notes).
  Index builds() const { return builds_; }
  /// Rows searched again while the rest of the list was kept (for tests and the notes).
  Index rows_searched() const { return rows_searched_; }

 private:
  /// The rows kept by id, or false when the list has to be built anew.
  bool keep_rows(std::span<const Vec<D>> a, const Numbering& number_a, Real reach, Real moved_b);
  void index_rows();  // row_of_id_ from a_.ids, and indexed_

  struct Side {
    std::vector<Vec<D>> x;  // positions at the build
    std::vector<std::int64_t> ids;
    std::uint64_t revision = 0;
    bool known = false;
    /// How far the set has moved since the build (+inf when renumbered or not finite).
    Real moved(std::span<const Vec<D>> now, const Numbering& n) const;
    void keep(std::span<const Vec<D>> now, const Numbering& n);
  };
  Side a_, b_;       // a_.x: each row's point where its row was searched
  Real radius_ = 0;  // the radius of the build; 0: none
  neighbors::NeighborList list_;
  Index builds_ = 0;
  Index rows_searched_ = 0;
  // The rows by id (when the first set has ids), made when a renumbered first set is first
  // looked up after a build (indexed_): a table over the ids' range from first_id_ when they
  // are dense (row_by_id_, -1 for none), else the ids ascending with their rows (row_of_id_).
  std::vector<Index> row_by_id_;
  std::int64_t first_id_ = 0;
  std::vector<std::pair<std::int64_t, Index>> row_of_id_;
  bool indexed_ = false;
  Index row_of(std::int64_t id) const;        // -1: no row of that id
  neighbors::NeighborList spare_, searched_;  // scratch of keep_rows, kept for their capacity
  neighbors::CrossIndex<D> b_index_;          // b_.x bucketed, at the first keep_rows of a build
};

/// The candidates of the points of a first set that are near the second: row k is point[k]'s,
/// the points ascending, each row ascending. Points with no candidate have no row. The rows
/// are views of the lists that hold them, valid until the next search.
struct NearRows {
  std::vector<Index> point;
  std::vector<std::span<const Index>> rows;

  std::span<const Index> of(std::size_t k) const { return rows[k]; }
  void clear() {
    point.clear();
    rows.clear();
  }
  /// Appends point i's row (after the rows of lower points).
  void add(Index i, std::span<const Index> row) {
    point.push_back(i);
    rows.push_back(row);
  }
};

/// A kept candidate list for a first set of many points of which few are near the second (a
/// soil bed against a plate's surface, thousands of grains for a few hundred in reach), kept
/// by the first set's ids rather than in its order: each id keeps its row and the position its
/// row was searched at, so a re-sort of the set costs nothing and a step costs one pass over
/// the set (which points moved past the margin, which have candidates) plus the search of the
/// points that moved too far. CrossCandidates, whose rows follow the set's order, rebuilds or
/// re-indexes all of them then. The guarantee is CrossCandidates's: every row holds the
/// second set's points within the reach, ascending, so the searches filtering by their own
/// test find the hits of a fresh list bit for bit. Without ids, or with ids too sparse for a
/// table over their range, the rows come from a CrossCandidates.
template <int D>
class NearCandidates {
 public:
  static constexpr Real kMarginFraction = CrossCandidates<D>::kMarginFraction;

  /// The rows of the points of a with a candidate in b within `reach` (and more, see above).
  const NearRows& find(std::span<const Vec<D>> a, const Numbering& number_a,
                       std::span<const Vec<D>> b, const Numbering& number_b, Real reach);

  /// Lists built for every point so far, and rows searched again (for tests and the notes).
  Index builds() const { return builds_ + by_order_.builds(); }
  Index rows_searched() const { return rows_searched_ + by_order_.rows_searched(); }

 private:
  // Every point of a searched afresh against b (b's margin starts anew); false when a's ids
  // do not fit a table, which then leaves the rows to by_order_.
  bool build(std::span<const Vec<D>> a, const Numbering& number_a, std::span<const Vec<D>> b,
             const Numbering& number_b, Real reach);
  // The slot of an id in the tables (-1: outside them).
  Index slot_of(std::int64_t id) const {
    const auto s = static_cast<std::uint64_t>(id) - static_cast<std::uint64_t>(first_id_);
    return s < x_row_.size() ? static_cast<Index>(s) : -1;
  }
  // x_at_ and listed_at_ for the set's order `ids` (when it is not that of the last find).
  void align(std::span<const std::int64_t> ids);
  // rows_: the rows of `points` (ascending; in the table) that have candidates.
  void gather(std::span<const std::int64_t> ids, std::span<const Index> points);

  std::vector<Vec<D>> b_x_;  // the second set at the build
  std::vector<std::int64_t> b_ids_;
  std::uint64_t b_revision_ = 0;
  bool b_known_ = false;
  Real radius_ = 0;  // the radius of the build; 0: none
  // Per id from first_id_: where its row was searched (NaN: never), and its row.
  std::int64_t first_id_ = 0;
  std::vector<Vec<D>> x_row_;
  std::vector<std::vector<Index>> row_;
  std::vector<char> listed_;  // whether the row holds any candidate
  // The same per point of the set in its order at the last find (ids_), which the pass over
  // the set reads in order; made again from the tables when the order changes (a re-sort).
  std::vector<std::int64_t> ids_;
  std::vector<Vec<D>> x_at_;
  std::vector<char> listed_at_;
  NearRows rows_;
  CrossCandidates<D> by_order_;  // without a usable table of ids
  neighbors::NeighborList searched_;
  neighbors::CrossIndex<D> b_index_;  // b_x_ bucketed, at the first search again of a build
  Index builds_ = 0;
  Index rows_searched_ = 0;
};

/// |x - y|^2 as the neighbour search computes it (the same operations in the same order), so
/// that a search filtering a kept list by `d2 <= reach^2` keeps exactly the pairs a fresh list
/// of that reach holds.
template <int D>
inline Real search_distance_sq(const Vec<D>& candidate, const Vec<D>& query) {
  const Real dx = candidate[0] - query[0];
  const Real dy = candidate[1] - query[1];
  Real d2 = dx * dx + dy * dy;
  if constexpr (D == 3) {
    const Real dz = candidate[2] - query[2];
    d2 += dz * dz;
  }
  return d2;
}

}  // namespace crater::contact
