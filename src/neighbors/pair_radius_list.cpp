// build_pair_radius_list: levels of doubling radius, each searched by cross lists at its own
// radius, then merged row by row (pair_radius_list.hpp).
#include "neighbors/pair_radius_list.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <vector>

#include "parallel/parallel.hpp"

namespace crater::neighbors {

namespace {

constexpr Real kInfinity = std::numeric_limits<Real>::infinity();

// The radii of `reach` checked positive and finite (`what` names the set in the error).
void check_reach(std::span<const Real> reach, const char* what) {
  const Index n = static_cast<Index>(reach.size());
  const auto r_of = [&](Index i) { return reach[static_cast<std::size_t>(i)]; };
  const std::vector<Index> bad =
      parallel::select(n, [&](Index i) { return !(r_of(i) > 0) || !std::isfinite(r_of(i)); });
  if (!bad.empty())
    throw std::invalid_argument(
        fmt::format("neighbour search: radius must be positive and finite, got {:.9g} at {}{}",
                    r_of(bad.front()), what, bad.front()));
}

// One set of points with a radius each, cut into levels of doubling radius: level L holds the
// points with r_min 2^(L-1) < reach <= r_min 2^L (level 0: reach <= r_min), r_min the least
// radius of both sets (exact doublings).
template <int D>
struct Levels {
  std::span<const Vec<D>> x;
  std::span<const Real> reach;
  std::vector<int> level;                // per point
  std::vector<std::vector<Index>> of;    // per level its points, ascending
  std::vector<std::vector<Index>> upto;  // per level the points of it and below, ascending
  std::vector<std::vector<Index>> row;   // row[L][i]: i's place in upto[L], -1 if not there

  Levels(std::span<const Vec<D>> x_, std::span<const Real> reach_, Real r_min)
      : x(x_), reach(reach_), level(x_.size()) {
    const Index n = static_cast<Index>(x.size());
    parallel::for_each(n, [&](Index i) {
      int l = 0;
      for (Real top = r_min; reach[static_cast<std::size_t>(i)] > top; top *= 2)
        ++l;
      level[static_cast<std::size_t>(i)] = l;
    });
  }
  Index size() const { return static_cast<Index>(x.size()); }
  int top() const {
    return static_cast<int>(parallel::max_over(
        size(), -1.0, [&](Index i) { return Real(level[static_cast<std::size_t>(i)]); }));
  }
  void cut(int levels) {
    of.resize(static_cast<std::size_t>(levels));
    upto.resize(static_cast<std::size_t>(levels));
    row.resize(static_cast<std::size_t>(levels));
    for (int l = 0; l < levels; ++l) {
      const auto ul = static_cast<std::size_t>(l);
      of[ul] = parallel::select(size(),
                                [&](Index i) { return level[static_cast<std::size_t>(i)] == l; });
      upto[ul] = parallel::select(size(),
                                  [&](Index i) { return level[static_cast<std::size_t>(i)] <= l; });
      row[ul].assign(static_cast<std::size_t>(size()), -1);
      parallel::for_each(static_cast<Index>(upto[ul].size()), [&](Index k) {
        row[ul][static_cast<std::size_t>(upto[ul][static_cast<std::size_t>(k)])] = k;
      });
    }
  }
  Real largest(int l) const {
    const std::vector<Index>& p = of[static_cast<std::size_t>(l)];
    return parallel::max_over(static_cast<Index>(p.size()), 0.0, [&](Index k) {
      return reach[static_cast<std::size_t>(p[static_cast<std::size_t>(k)])];
    });
  }
  std::vector<Vec<D>> gather(const std::vector<Index>& idx) const {
    std::vector<Vec<D>> p(idx.size());
    parallel::for_each(static_cast<Index>(idx.size()), [&](Index k) {
      p[static_cast<std::size_t>(k)] =
          x[static_cast<std::size_t>(idx[static_cast<std::size_t>(k)])];
    });
    return p;
  }
};

// For each point i of a, the points j of b with |a_i - b_j| <= max(reach_a[i], reach_b[j]),
// ascending; `self` (a and b the same set) leaves out j = i. Per level L the pairs whose larger
// level is b's L (a's points of levels <= L against b's of L, call 2L) or a's L (a's of L
// against b's below L, call 2L + 1): every ordered pair is in exactly one call's row of i, at
// the largest radius of level L over both sets.
template <int D>
void build_radius_lists(std::span<const Vec<D>> a, std::span<const Real> reach_a,
                        std::span<const Vec<D>> b, std::span<const Real> reach_b, bool self,
                        NeighborList& out, std::vector<NeighborList>& scratch) {
  const Index na = static_cast<Index>(a.size()), nb = static_cast<Index>(b.size());
  out.offsets.assign(static_cast<std::size_t>(na + 1), 0);
  out.indices.clear();
  if (na == 0 || nb == 0) return;
  const auto lowest = [](std::span<const Real> r) {
    return -parallel::max_over(static_cast<Index>(r.size()), -kInfinity,
                               [&](Index i) { return -r[static_cast<std::size_t>(i)]; });
  };
  const auto highest = [](std::span<const Real> r) {
    return parallel::max_over(static_cast<Index>(r.size()), 0.0,
                              [&](Index i) { return r[static_cast<std::size_t>(i)]; });
  };
  const Real r_min = std::min(lowest(reach_a), lowest(reach_b));
  const Real r_max = std::max(highest(reach_a), highest(reach_b));
  if (r_max == r_min) {  // one radius: the fixed-radius list is the same list
    if (self)
      build_neighbor_list<D>(a, r_max, Pairs::Full, out);
    else
      build_cross_list<D>(a, b, r_max, out);
    return;
  }
  Levels<D> la(a, reach_a, r_min);
  std::optional<Levels<D>> lb_own;
  if (!self) lb_own.emplace(b, reach_b, r_min);
  Levels<D>& lb = self ? la : *lb_own;
  const int levels = 1 + std::max(la.top(), lb.top());
  la.cut(levels);
  if (!self) lb.cut(levels);
  scratch.resize(static_cast<std::size_t>(2 * levels));
  for (int l = 0; l < levels; ++l) {
    const auto ul = static_cast<std::size_t>(l);
    const Real radius = std::max(la.of[ul].empty() ? Real(0) : la.largest(l),
                                 lb.of[ul].empty() ? Real(0) : lb.largest(l));
    if (!lb.of[ul].empty() && !la.upto[ul].empty()) {
      const std::vector<Vec<D>> xq = la.gather(la.upto[ul]), xc = lb.gather(lb.of[ul]);
      build_cross_list<D>(std::span<const Vec<D>>(xq), std::span<const Vec<D>>(xc), radius,
                          scratch[2 * ul]);
    } else {
      scratch[2 * ul] = NeighborList{};
    }
    if (l > 0 && !la.of[ul].empty() && !lb.upto[ul - 1].empty()) {
      const std::vector<Vec<D>> xq = la.gather(la.of[ul]), xc = lb.gather(lb.upto[ul - 1]);
      build_cross_list<D>(std::span<const Vec<D>>(xq), std::span<const Vec<D>>(xc), radius,
                          scratch[2 * ul + 1]);
    } else {
      scratch[2 * ul + 1] = NeighborList{};
    }
  }
  // Each row: its entries of every call, kept when within either radius, then sorted.
  const auto visit = [&](Index i, auto&& f) {
    const int li = la.level[static_cast<std::size_t>(i)];
    const Real ri = reach_a[static_cast<std::size_t>(i)];
    const auto keep = [&](Index j) {
      const Real r = std::max(ri, reach_b[static_cast<std::size_t>(j)]);
      if (!(self && j == i) &&
          (a[static_cast<std::size_t>(i)] - b[static_cast<std::size_t>(j)]).squaredNorm() <= r * r)
        f(j);
    };
    for (int l = li; l < levels; ++l) {
      const auto ul = static_cast<std::size_t>(l);
      if (lb.of[ul].empty()) continue;
      for (const Index k : scratch[2 * ul].of(la.row[ul][static_cast<std::size_t>(i)]))
        keep(lb.of[ul][static_cast<std::size_t>(k)]);
    }
    if (li > 0 && !lb.upto[static_cast<std::size_t>(li) - 1].empty()) {
      const auto ul = static_cast<std::size_t>(li);
      const Index me = static_cast<Index>(std::lower_bound(la.of[ul].begin(), la.of[ul].end(), i) -
                                          la.of[ul].begin());
      for (const Index k : scratch[2 * ul + 1].of(me))
        keep(lb.upto[ul - 1][static_cast<std::size_t>(k)]);
    }
  };
  parallel::for_each(
      na,
      [&](Index i) {
        Index count = 0;
        visit(i, [&](Index) { ++count; });
        out.offsets[static_cast<std::size_t>(i) + 1] = count;
      },
      parallel::Cost::heavy);
  for (Index i = 0; i < na; ++i)
    out.offsets[static_cast<std::size_t>(i) + 1] += out.offsets[static_cast<std::size_t>(i)];
  out.indices.resize(static_cast<std::size_t>(out.offsets[static_cast<std::size_t>(na)]));
  parallel::for_each(
      na,
      [&](Index i) {
        Index* begin = out.indices.data() + out.offsets[static_cast<std::size_t>(i)];
        Index* at = begin;
        visit(i, [&](Index j) { *at++ = j; });
        std::sort(begin, at);
      },
      parallel::Cost::heavy);
}

}  // namespace

template <int D>
void build_pair_radius_list(std::span<const Vec<D>> x, std::span<const Real> reach,
                            NeighborList& out, std::vector<NeighborList>& scratch) {
  check_reach(reach, "point ");
  build_radius_lists<D>(x, reach, x, reach, true, out, scratch);
}

template <int D>
void build_cross_radius_list(std::span<const Vec<D>> a, std::span<const Real> reach_a,
                             std::span<const Vec<D>> b, std::span<const Real> reach_b,
                             NeighborList& out, std::vector<NeighborList>& scratch) {
  if (reach_a.size() != a.size() || reach_b.size() != b.size())
    throw std::invalid_argument("neighbour search: one radius per point is needed");
  check_reach(reach_a, "query point ");
  check_reach(reach_b, "candidate point ");
  build_radius_lists<D>(a, reach_a, b, reach_b, false, out, scratch);
}

template void build_pair_radius_list<2>(std::span<const Vec<2>>, std::span<const Real>,
                                        NeighborList&, std::vector<NeighborList>&);
template void build_pair_radius_list<3>(std::span<const Vec<3>>, std::span<const Real>,
                                        NeighborList&, std::vector<NeighborList>&);
template void build_cross_radius_list<2>(std::span<const Vec<2>>, std::span<const Real>,
                                         std::span<const Vec<2>>, std::span<const Real>,
                                         NeighborList&, std::vector<NeighborList>&);
template void build_cross_radius_list<3>(std::span<const Vec<3>>, std::span<const Real>,
                                         std::span<const Vec<3>>, std::span<const Real>,
                                         NeighborList&, std::vector<NeighborList>&);

}  // namespace crater::neighbors
