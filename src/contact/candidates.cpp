// Candidate lists kept between steps; see candidates.hpp.
#include "contact/candidates.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/index.hpp"
#include "parallel/parallel.hpp"

namespace crater::contact {

namespace {

// How far a set has moved since it was at `x` with these ids and revision: +inf when it was
// renumbered, or for a point that is not finite (which a new build then reports as the
// neighbour search does).
template <int D>
Real moved_since(std::span<const Vec<D>> now, const Numbering& n, const std::vector<Vec<D>>& x,
                 const std::vector<std::int64_t>& ids, std::uint64_t revision, bool known) {
  constexpr Real kInf = std::numeric_limits<Real>::infinity();
  if (!known || !n.known || now.size() != x.size() || n.revision != revision) return kInf;
  if (!n.ids.empty() && n.ids.size() != ids.size()) return kInf;
  const bool by_id = !n.ids.empty();
  const Real moved_sq = parallel::max_over(static_cast<Index>(now.size()), 0.0, [&](Index i) {
    const auto k = static_cast<std::size_t>(i);
    if (by_id && n.ids[k] != ids[k]) return kInf;
    const Real d2 = (now[k] - x[k]).squaredNorm();
    return std::isfinite(d2) ? d2 : kInf;
  });
  return std::sqrt(moved_sq);
}

}  // namespace

template <int D>
Real CrossCandidates<D>::Side::moved(std::span<const Vec<D>> now, const Numbering& n) const {
  return moved_since<D>(now, n, x, ids, revision, known);
}

template <int D>
void CrossCandidates<D>::Side::keep(std::span<const Vec<D>> now, const Numbering& n) {
  x.assign(now.begin(), now.end());
  ids.assign(n.ids.begin(), n.ids.end());
  revision = n.revision;
  known = n.known;
}

template <int D>
bool CrossCandidates<D>::keep_rows(std::span<const Vec<D>> a, const Numbering& number_a, Real reach,
                                   Real moved_b) {
  if (!number_a.known || !a_.known || number_a.ids.size() != a.size() || a_.ids.empty())
    return false;
  const Index n = static_cast<Index>(a.size());
  // Each point's row at the build, when its id was there and it has not moved past what the
  // margin left by the second set's motion covers; -1: its row is searched again. Where the
  // set holds the ids of the rows in their order (one rank's whole part between its re-sorts),
  // point k's row is row k; else the rows are looked up by id.
  const bool aligned =
      std::equal(number_a.ids.begin(), number_a.ids.end(), a_.ids.begin(), a_.ids.end());
  if (!aligned && !indexed_) index_rows();
  std::vector<Index> from(a.size(), -1);
  parallel::for_each(n, [&](Index i) {
    const auto k = static_cast<std::size_t>(i);
    const Index row = aligned ? i : row_of(number_a.ids[k]);
    if (row < 0) return;
    const Real d = (a[k] - a_.x[static_cast<std::size_t>(row)]).norm();
    if (std::isfinite(d) && (reach + d + moved_b) * (1 + Real(1e-9)) <= radius_) from[k] = row;
  });
  const std::vector<Index> again = parallel::select(n, [&](Index i) { return from[at(i)] < 0; });
  // Past half the rows a new build costs less, and it starts the second set's margin afresh.
  if (2 * again.size() > a.size()) return false;
  std::vector<Vec<D>> x(again.size());
  for (std::size_t q = 0; q < again.size(); ++q) {
    x[q] = a[at(again[q])];
    if (!x[q].allFinite()) return false;  // the new build reports it as the search does
  }
  // Against the second set as it was at the build, bucketed once for the rows of every step
  // until the next build.
  if (!b_index_.built()) b_index_.build(std::span<const Vec<D>>(b_.x), radius_);
  b_index_.query(std::span<const Vec<D>>(x), searched_);
  // The new list: each row from the old list or from the search, in the first set's order.
  std::vector<Index> searched_row(a.size(), -1);
  for (std::size_t q = 0; q < again.size(); ++q)
    searched_row[at(again[q])] = static_cast<Index>(q);
  auto row = [&](Index i) {
    const auto k = static_cast<std::size_t>(i);
    return from[k] >= 0 ? list_.of(from[k]) : searched_.of(searched_row[k]);
  };
  spare_.offsets.resize(a.size() + 1);
  spare_.offsets[0] = 0;
  for (Index i = 0; i < n; ++i)
    spare_.offsets[at(i) + 1] = spare_.offsets[at(i)] + static_cast<Index>(row(i).size());
  spare_.indices.resize(at(spare_.offsets[a.size()]));
  std::vector<Vec<D>> x_row(a.size());
  parallel::for_each(n, [&](Index i) {
    const auto k = static_cast<std::size_t>(i);
    const auto r = row(i);
    std::copy(r.begin(), r.end(), spare_.indices.begin() + spare_.offsets[k]);
    x_row[k] = from[k] >= 0 ? a_.x[at(from[k])] : a[k];
  });
  std::swap(list_, spare_);
  a_.x = std::move(x_row);
  a_.ids.assign(number_a.ids.begin(), number_a.ids.end());
  a_.revision = number_a.revision;
  indexed_ = false;
  rows_searched_ += static_cast<Index>(again.size());
  return true;
}

// Ids of a part's particles are mostly a dense range (numbered at creation, a few removed):
// then a table over the range, else the ids sorted with their rows for a binary search.
template <int D>
void CrossCandidates<D>::index_rows() {
  indexed_ = true;
  row_of_id_.clear();
  row_by_id_.clear();
  if (a_.ids.empty()) return;
  const auto [lo, hi] = std::minmax_element(a_.ids.begin(), a_.ids.end());
  first_id_ = *lo;
  const auto n = a_.ids.size();
  if (static_cast<std::uint64_t>(*hi) - static_cast<std::uint64_t>(*lo) < 4 * n + 64) {
    row_by_id_.assign(static_cast<std::size_t>(*hi - *lo) + 1, -1);
    for (std::size_t i = 0; i < n; ++i)
      row_by_id_[static_cast<std::size_t>(a_.ids[i] - first_id_)] = static_cast<Index>(i);
    return;
  }
  row_of_id_.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    row_of_id_[i] = {a_.ids[i], static_cast<Index>(i)};
  std::sort(row_of_id_.begin(), row_of_id_.end());
}

template <int D>
Index CrossCandidates<D>::row_of(std::int64_t id) const {
  if (!row_by_id_.empty()) {
    if (id < first_id_ || static_cast<std::uint64_t>(id - first_id_) >= row_by_id_.size())
      return -1;
    return row_by_id_[static_cast<std::size_t>(id - first_id_)];
  }
  const auto hit = std::lower_bound(row_of_id_.begin(), row_of_id_.end(),
                                    std::pair<std::int64_t, Index>(id, -1));
  return hit == row_of_id_.end() || hit->first != id ? -1 : hit->second;
}

template <int D>
const neighbors::NeighborList& CrossCandidates<D>::find(std::span<const Vec<D>> a,
                                                        const Numbering& number_a,
                                                        std::span<const Vec<D>> b,
                                                        const Numbering& number_b, Real reach) {
  // A pair within `reach` now was within reach + (moved a) + (moved b) at the build; the
  // factor covers the rounding of that sum and of the search's own distances.
  if (radius_ > 0) {
    const Real moved_b = b_.moved(b, number_b);
    if (std::isfinite(moved_b)) {
      if ((reach + a_.moved(a, number_a) + moved_b) * (1 + Real(1e-9)) <= radius_) return list_;
      if (keep_rows(a, number_a, reach, moved_b)) return list_;
    }
  }
  const Real radius = reach * (1 + kMarginFraction);
  radius_ = 0;  // none, should the build throw
  b_index_.clear();
  neighbors::build_cross_list<D>(a, b, radius, list_);
  radius_ = radius;
  a_.keep(a, number_a);
  b_.keep(b, number_b);
  indexed_ = false;  // index_rows when a renumbered first set needs it
  ++builds_;
  return list_;
}

template <int D>
bool NearCandidates<D>::build(std::span<const Vec<D>> a, const Numbering& number_a,
                              std::span<const Vec<D>> b, const Numbering& number_b, Real reach) {
  const std::span<const std::int64_t> ids = number_a.ids;
  const auto [lo, hi] = std::minmax_element(ids.begin(), ids.end());
  if (static_cast<std::uint64_t>(*hi) - static_cast<std::uint64_t>(*lo) >= 4 * ids.size() + 64)
    return false;
  const Real radius = reach * (1 + kMarginFraction);
  radius_ = 0;  // none, should the search throw
  b_index_.clear();
  neighbors::build_cross_list<D>(a, b, radius, searched_);
  first_id_ = *lo;
  const auto slots = static_cast<std::size_t>(*hi - *lo) + 1;
  x_row_.assign(slots, Vec<D>::Constant(std::numeric_limits<Real>::quiet_NaN()));
  row_.resize(slots);
  for (auto& r : row_)
    r.clear();
  listed_.assign(slots, 0);
  // The tables by id, and the same in the set's order (what align() would make of them).
  ids_.assign(ids.begin(), ids.end());
  x_at_.assign(a.begin(), a.end());
  listed_at_.resize(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto s = static_cast<std::size_t>(ids[i] - first_id_);
    x_row_[s] = a[i];
    const auto r = searched_.of(static_cast<Index>(i));
    row_[s].assign(r.begin(), r.end());
    listed_[s] = listed_at_[i] = !r.empty();
  }
  b_x_.assign(b.begin(), b.end());
  b_ids_.assign(number_b.ids.begin(), number_b.ids.end());
  b_revision_ = number_b.revision;
  b_known_ = number_b.known;
  radius_ = radius;
  ++builds_;
  return true;
}

template <int D>
void NearCandidates<D>::align(std::span<const std::int64_t> ids) {
  if (std::equal(ids.begin(), ids.end(), ids_.begin(), ids_.end())) return;
  ids_.assign(ids.begin(), ids.end());
  const Index n = static_cast<Index>(ids.size());
  x_at_.resize(ids.size());
  listed_at_.resize(ids.size());
  parallel::for_each(n, [&](Index i) {
    const Index s = slot_of(ids[at(i)]);
    x_at_[at(i)] = s < 0 ? Vec<D>::Constant(std::numeric_limits<Real>::quiet_NaN()) : x_row_[at(s)];
    listed_at_[at(i)] = s < 0 ? 0 : listed_[at(s)];
  });
}

template <int D>
void NearCandidates<D>::gather(std::span<const std::int64_t> ids, std::span<const Index> points) {
  rows_.clear();
  for (const Index i : points)
    if (listed_at_[at(i)]) rows_.add(i, row_[at(slot_of(ids[at(i)]))]);
}

template <int D>
const NearRows& NearCandidates<D>::find(std::span<const Vec<D>> a, const Numbering& number_a,
                                        std::span<const Vec<D>> b, const Numbering& number_b,
                                        Real reach) {
  const std::span<const std::int64_t> ids = number_a.ids;
  const Index n = static_cast<Index>(a.size());
  const bool by_id = number_a.known && !ids.empty() && ids.size() == a.size();
  if (by_id && radius_ > 0) {
    const Real moved_b = moved_since<D>(b, number_b, b_x_, b_ids_, b_revision_, b_known_);
    // A pair within `reach` now was within reach + (moved a) + (moved b) when its row was
    // searched: a row is kept while its point has moved by `allow` at most (the factor covers
    // the rounding of that sum and of the search's distances).
    const Real allow = radius_ / (1 + Real(1e-9)) - reach - moved_b;
    const Real allow_sq = allow * allow;
    if (std::isfinite(moved_b) && allow >= 0) {
      align(ids);
      // One pass over the set, in its order: the points with a row, or whose row is searched
      // again (not finite: never searched, or an id outside the table).
      auto again = [&](Index i) { return !((a[at(i)] - x_at_[at(i)]).squaredNorm() <= allow_sq); };
      const std::vector<Index> near =
          parallel::select(n, [&](Index i) { return listed_at_[at(i)] || again(i); });
      std::vector<Index> redo;
      bool fits = true;
      for (const Index i : near) {
        if (!again(i)) continue;
        redo.push_back(i);
        // An id new to the table, or a point not finite (which the build reports as the
        // search does): a new build.
        if (slot_of(ids[at(i)]) < 0 || !a[at(i)].allFinite()) fits = false;
      }
      // Past half the points a new build costs less, and it starts b's margin afresh.
      if (fits && 2 * redo.size() <= a.size()) {
        std::vector<Vec<D>> x(redo.size());
        for (std::size_t q = 0; q < redo.size(); ++q)
          x[q] = a[at(redo[q])];
        if (!b_index_.built()) b_index_.build(std::span<const Vec<D>>(b_x_), radius_);
        b_index_.query(std::span<const Vec<D>>(x), searched_);
        for (std::size_t q = 0; q < redo.size(); ++q) {
          const auto i = at(redo[q]);
          const auto s = at(slot_of(ids[i]));
          const auto r = searched_.of(static_cast<Index>(q));
          row_[s].assign(r.begin(), r.end());
          listed_[s] = listed_at_[i] = !r.empty();
          x_row_[s] = x_at_[i] = x[q];
        }
        rows_searched_ += static_cast<Index>(redo.size());
        gather(ids, near);
        return rows_;
      }
    }
  }
  // A new build's rows (the searched list, in the set's order), or without a table of ids
  // those of a list in the set's order: the rows with candidates.
  const neighbors::NeighborList& list = by_id && n > 0 && build(a, number_a, b, number_b, reach)
                                            ? searched_
                                            : by_order_.find(a, number_a, b, number_b, reach);
  rows_.clear();
  for (Index i = 0; i < list.size(); ++i)
    if (!list.of(i).empty()) rows_.add(i, list.of(i));
  return rows_;
}

template class CrossCandidates<2>;
template class CrossCandidates<3>;
template class NearCandidates<2>;
template class NearCandidates<3>;

}  // namespace crater::contact
