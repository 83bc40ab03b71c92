// Candidate lists kept between steps; see candidates.hpp.
#include "contact/candidates.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/index.hpp"
#include "parallel/parallel.hpp"

namespace crater::contact {

template <int D>
Real CrossCandidates<D>::Side::moved(std::span<const Vec<D>> now, const Numbering& n) const {
  constexpr Real kInf = std::numeric_limits<Real>::infinity();
  if (!known || !n.known || now.size() != x.size() || n.revision != revision) return kInf;
  if (!n.ids.empty() && n.ids.size() != ids.size()) return kInf;
  const bool by_id = !n.ids.empty();
  // One pass: the largest squared displacement, or +inf for a renumbered or non-finite point
  // (which a new build then reports as the neighbour search does).
  const Real moved_sq = parallel::max_over(static_cast<Index>(now.size()), 0.0, [&](Index i) {
    const auto k = static_cast<std::size_t>(i);
    if (by_id && n.ids[k] != ids[k]) return kInf;
    const Real d2 = (now[k] - x[k]).squaredNorm();
    return std::isfinite(d2) ? d2 : kInf;
  });
  return std::sqrt(moved_sq);
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
  neighbors::build_cross_list<D>(std::span<const Vec<D>>(x), std::span<const Vec<D>>(b_.x), radius_,
                                 searched_);
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
  neighbors::build_cross_list<D>(a, b, radius, list_);
  radius_ = radius;
  a_.keep(a, number_a);
  b_.keep(b, number_b);
  indexed_ = false;  // index_rows when a renumbered first set needs it
  ++builds_;
  return list_;
}

template class CrossCandidates<2>;
template class CrossCandidates<3>;

}  // namespace crater::contact
