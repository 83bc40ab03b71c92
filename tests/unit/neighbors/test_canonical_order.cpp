// The order a part sorts its entities into (cell_sort_order with ids) must be the same on a rank
// holding a share of them as on the whole set (issue 29, docs/distributed.md): the order of any
// two entities depends only on their positions, ids and the cell size. Checked here as a
// rank would see it: a region of the set with its halo, given in shuffled order, sorts into the
// whole set's order restricted to it, and the neighbour lists built on it list each of the
// region's entities' partners in the same order of ids as on the whole set.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include "neighbors/cell_grid.hpp"
#include "neighbors/neighbor_list.hpp"

namespace crater::neighbors {
namespace {

template <int D>
struct Points {
  std::vector<Vec<D>> x;
  std::vector<std::int64_t> id;
};

// n points in [lo, lo + 1)^D, ids a random permutation (not the index).
template <int D>
Points<D> random_points(std::size_t n, Real lo, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<Real> u(lo, lo + 1.0);
  Points<D> p;
  p.x.resize(n);
  for (auto& q : p.x)
    for (int a = 0; a < D; ++a)
      q[a] = u(gen);
  p.id.resize(n);
  std::iota(p.id.begin(), p.id.end(), std::int64_t{0});
  std::shuffle(p.id.begin(), p.id.end(), gen);
  return p;
}

template <int D>
std::vector<std::int64_t> sorted_ids(const Points<D>& p, Real h) {
  const auto order = cell_sort_order<D>(p.x, h, p.id);
  std::vector<std::int64_t> ids;
  for (Index i : order)
    ids.push_back(p.id[static_cast<std::size_t>(i)]);
  return ids;
}

// The points of `all` with keep(x), in shuffled order.
template <int D, class Keep>
Points<D> subset(const Points<D>& all, Keep keep, unsigned seed) {
  std::vector<std::size_t> pick;
  for (std::size_t i = 0; i < all.x.size(); ++i)
    if (keep(all.x[i])) pick.push_back(i);
  std::mt19937_64 gen(seed);
  std::shuffle(pick.begin(), pick.end(), gen);
  Points<D> s;
  for (std::size_t i : pick) {
    s.x.push_back(all.x[i]);
    s.id.push_back(all.id[i]);
  }
  return s;
}

template <int D>
void check_restriction(Real lo) {
  SCOPED_TRACE(::testing::Message() << D << "D, box from " << lo);
  const Real h = 0.1;       // a few points per cell, as in a bed of grains
  const Real reach = 0.12;  // a rank's halo
  const auto all = random_points<D>(D == 3 ? 6000 : 3000, lo, 11);
  const auto whole = sorted_ids<D>(all, h);
  std::vector<std::size_t> rank_of_id(whole.size());  // position in the whole order
  for (std::size_t k = 0; k < whole.size(); ++k)
    rank_of_id[static_cast<std::size_t>(whole[k])] = k;

  // Three "ranks": slabs and a corner block, each with its halo.
  const Real c = lo + 0.37;
  const std::vector<std::pair<Vec<D>, Vec<D>>> regions = {
      {Vec<D>::Constant(lo - 1), Vec<D>::Constant(lo + 2) - Vec<D>::UnitX() * (lo + 2 - c)},
      {Vec<D>::Constant(lo - 1) + Vec<D>::UnitX() * (c - (lo - 1)), Vec<D>::Constant(lo + 2)},
      {Vec<D>::Constant(c), Vec<D>::Constant(lo + 2)},
  };
  for (std::size_t r = 0; r < regions.size(); ++r) {
    SCOPED_TRACE(::testing::Message() << "region " << r);
    const auto& [rlo, rhi] = regions[r];
    const auto inside = [&](const Vec<D>& q) {
      return (q.array() >= rlo.array()).all() && (q.array() < rhi.array()).all();
    };
    const auto near = [&](const Vec<D>& q) {
      const Vec<D> out = (rlo - q).cwiseMax(q - rhi).cwiseMax(Vec<D>::Zero());
      return out.squaredNorm() <= reach * reach;
    };
    const auto share = subset<D>(all, near, 100 + static_cast<unsigned>(r));
    // The precondition: the share's grid has the whole set's cell size (no memory guard).
    ASSERT_EQ(make_grid_spec<D>(share.x, h).cell_size, make_grid_spec<D>(all.x, h).cell_size);

    // The share's order is the whole order restricted to the share.
    const auto got = sorted_ids<D>(share, h);
    std::vector<std::int64_t> expected(got);
    std::sort(expected.begin(), expected.end(), [&](std::int64_t a, std::int64_t b) {
      return rank_of_id[static_cast<std::size_t>(a)] < rank_of_id[static_cast<std::size_t>(b)];
    });
    ASSERT_EQ(got, expected);

    // Neighbour rows of the region's own points: the same ids in the same order.
    const auto permute = [](const Points<D>& p, const std::vector<Index>& order) {
      Points<D> s;
      for (Index i : order) {
        s.x.push_back(p.x[static_cast<std::size_t>(i)]);
        s.id.push_back(p.id[static_cast<std::size_t>(i)]);
      }
      return s;
    };
    const auto whole_sorted = permute(all, cell_sort_order<D>(all.x, h, all.id));
    const auto share_sorted = permute(share, cell_sort_order<D>(share.x, h, share.id));
    NeighborList whole_list, share_list;
    const Real radius = 0.1;  // <= reach: a region point's partners are all in the share
    build_neighbor_list<D>(whole_sorted.x, radius, Pairs::Full, whole_list);
    build_neighbor_list<D>(share_sorted.x, radius, Pairs::Full, share_list);
    std::vector<std::size_t> whole_index_of_id(whole.size());
    for (std::size_t i = 0; i < whole_sorted.id.size(); ++i)
      whole_index_of_id[static_cast<std::size_t>(whole_sorted.id[i])] = i;
    std::size_t rows = 0;
    for (std::size_t i = 0; i < share_sorted.x.size(); ++i) {
      if (!inside(share_sorted.x[i])) continue;
      std::vector<std::int64_t> a, b;
      for (Index j : share_list.of(static_cast<Index>(i)))
        a.push_back(share_sorted.id[static_cast<std::size_t>(j)]);
      const auto w =
          static_cast<Index>(whole_index_of_id[static_cast<std::size_t>(share_sorted.id[i])]);
      for (Index j : whole_list.of(w))
        b.push_back(whole_sorted.id[static_cast<std::size_t>(j)]);
      ASSERT_EQ(a, b) << "row of id " << share_sorted.id[i];
      ++rows;
    }
    EXPECT_GT(rows, all.x.size() / 10);
  }
}

TEST(CanonicalOrder, AShareSortsIntoTheWholeOrder2D) {
  check_restriction<2>(0.0);
}

TEST(CanonicalOrder, AShareSortsIntoTheWholeOrder3D) {
  check_restriction<3>(0.0);
  // Away from the origin, where the lattice cells' indices are large.
  check_restriction<3>(1234.5678);
}

TEST(CanonicalOrder, WithoutIdsTheOrderFollowsTheInput) {
  // Without keys a cell keeps its points' input order: shuffling the input changes the order,
  // which is why the parts pass their ids.
  auto p = random_points<3>(3000, 0.0, 5);
  const auto ids_of = [&](const std::vector<Index>& order) {
    std::vector<std::int64_t> ids;
    for (Index i : order)
      ids.push_back(p.id[static_cast<std::size_t>(i)]);
    return ids;
  };
  const auto keyed = ids_of(cell_sort_order<3>(p.x, 0.1, p.id));
  const auto plain = ids_of(cell_sort_order<3>(p.x, 0.1));
  EXPECT_NE(keyed, plain);
  EXPECT_THROW(cell_sort_order<3>(p.x, 0.1, std::span<const std::int64_t>(p.id).first(10)),
               std::invalid_argument);
}

}  // namespace
}  // namespace crater::neighbors
