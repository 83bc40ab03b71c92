// build_pair_radius_list: levels of doubling radius, each searched by cross lists at its own
// radius, then merged row by row (pair_radius_list.hpp).
#include "neighbors/pair_radius_list.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "parallel/parallel.hpp"

namespace crater::neighbors {

namespace {
constexpr Real kInfinity = std::numeric_limits<Real>::infinity();
}  // namespace

template <int D>
void build_pair_radius_list(std::span<const Vec<D>> x, std::span<const Real> reach,
                            NeighborList& out, std::vector<NeighborList>& scratch) {
  const Index n = static_cast<Index>(x.size());
  out.offsets.assign(static_cast<std::size_t>(n + 1), 0);
  out.indices.clear();
  if (n == 0) return;
  const auto r_of = [&](Index i) { return reach[static_cast<std::size_t>(i)]; };
  const std::vector<Index> bad =
      parallel::select(n, [&](Index i) { return !(r_of(i) > 0) || !std::isfinite(r_of(i)); });
  if (!bad.empty())
    throw std::invalid_argument(
        fmt::format("neighbour search: radius must be positive and finite, got {:.9g} at point {}",
                    r_of(bad.front()), bad.front()));
  const Real r_min = -parallel::max_over(n, -kInfinity, [&](Index i) { return -r_of(i); });
  const Real r_max = parallel::max_over(n, 0.0, r_of);
  if (r_max == r_min) {  // one radius: the fixed-radius list is the same list
    build_neighbor_list<D>(x, r_max, Pairs::Full, out);
    return;
  }
  // Level of i: the least L with reach_i <= r_min 2^L (exact doublings).
  std::vector<int> level(static_cast<std::size_t>(n));
  parallel::for_each(n, [&](Index i) {
    int l = 0;
    for (Real top = r_min; r_of(i) > top; top *= 2)
      ++l;
    level[static_cast<std::size_t>(i)] = l;
  });
  const int levels = 1 + static_cast<int>(parallel::max_over(n, 0.0, [&](Index i) {
                       return Real(level[static_cast<std::size_t>(i)]);
                     }));
  const auto lv = [&](Index i) { return level[static_cast<std::size_t>(i)]; };
  // Per level L: its points (ascending) and the pairs whose larger level is L, both ways: the
  // points of levels <= L against those of L (call 2L), and those of L against the levels < L
  // (call 2L + 1). Every ordered pair (i, j) is in exactly one call's row of i.
  scratch.resize(static_cast<std::size_t>(2 * levels));
  std::vector<std::vector<Index>> of(static_cast<std::size_t>(levels));
  std::vector<std::vector<Index>> upto(static_cast<std::size_t>(levels));
  std::vector<Real> radius(static_cast<std::size_t>(levels));
  const auto gather = [&](const std::vector<Index>& idx) {
    std::vector<Vec<D>> p(idx.size());
    parallel::for_each(static_cast<Index>(idx.size()), [&](Index k) {
      p[static_cast<std::size_t>(k)] =
          x[static_cast<std::size_t>(idx[static_cast<std::size_t>(k)])];
    });
    return p;
  };
  // row[L][i]: the row of point i in call 2L (levels <= L), -1 if not a query there.
  std::vector<std::vector<Index>> row(static_cast<std::size_t>(levels));
  for (int l = 0; l < levels; ++l) {
    const auto ul = static_cast<std::size_t>(l);
    of[ul] = parallel::select(n, [&](Index i) { return lv(i) == l; });
    upto[ul] = parallel::select(n, [&](Index i) { return lv(i) <= l; });
    if (of[ul].empty()) continue;
    radius[ul] = parallel::max_over(static_cast<Index>(of[ul].size()), 0.0, [&](Index k) {
      return r_of(of[ul][static_cast<std::size_t>(k)]);
    });
    const std::vector<Vec<D>> xl = gather(of[ul]), xu = gather(upto[ul]);
    build_cross_list<D>(std::span<const Vec<D>>(xu), std::span<const Vec<D>>(xl), radius[ul],
                        scratch[2 * ul]);
    if (l > 0) {
      const std::vector<Vec<D>> xb = gather(upto[ul - 1]);
      build_cross_list<D>(std::span<const Vec<D>>(xl), std::span<const Vec<D>>(xb), radius[ul],
                          scratch[2 * ul + 1]);
    }
    row[ul].assign(static_cast<std::size_t>(n), -1);
    parallel::for_each(static_cast<Index>(upto[ul].size()), [&](Index k) {
      row[ul][static_cast<std::size_t>(upto[ul][static_cast<std::size_t>(k)])] = k;
    });
  }
  // Each row: its entries of every call, kept when within either radius, then sorted.
  const auto visit = [&](Index i, auto&& f) {
    const int li = lv(i);
    const auto keep = [&](Index j) {
      const Real r = std::max(r_of(i), r_of(j));
      if (j != i &&
          (x[static_cast<std::size_t>(i)] - x[static_cast<std::size_t>(j)]).squaredNorm() <= r * r)
        f(j);
    };
    for (int l = li; l < levels; ++l) {
      const auto ul = static_cast<std::size_t>(l);
      if (of[ul].empty()) continue;
      for (const Index k : scratch[2 * ul].of(row[ul][static_cast<std::size_t>(i)]))
        keep(of[ul][static_cast<std::size_t>(k)]);
    }
    if (li > 0) {
      const auto ul = static_cast<std::size_t>(li);
      const Index me =
          static_cast<Index>(std::lower_bound(of[ul].begin(), of[ul].end(), i) - of[ul].begin());
      for (const Index k : scratch[2 * ul + 1].of(me))
        keep(upto[ul - 1][static_cast<std::size_t>(k)]);
    }
  };
  parallel::for_each(
      n,
      [&](Index i) {
        Index count = 0;
        visit(i, [&](Index) { ++count; });
        out.offsets[static_cast<std::size_t>(i) + 1] = count;
      },
      parallel::Cost::heavy);
  for (Index i = 0; i < n; ++i)
    out.offsets[static_cast<std::size_t>(i) + 1] += out.offsets[static_cast<std::size_t>(i)];
  out.indices.resize(static_cast<std::size_t>(out.offsets[static_cast<std::size_t>(n)]));
  parallel::for_each(
      n,
      [&](Index i) {
        Index* begin = out.indices.data() + out.offsets[static_cast<std::size_t>(i)];
        Index* at = begin;
        visit(i, [&](Index j) { *at++ = j; });
        std::sort(begin, at);
      },
      parallel::Cost::heavy);
}

template void build_pair_radius_list<2>(std::span<const Vec<2>>, std::span<const Real>,
                                        NeighborList&, std::vector<NeighborList>&);
template void build_pair_radius_list<3>(std::span<const Vec<3>>, std::span<const Real>,
                                        NeighborList&, std::vector<NeighborList>&);

}  // namespace crater::neighbors
