// parallel::rcb (src/parallel/rcb.hpp): every entity owned once, each rank's weight within one
// entity's weight per level of cuts of its exact share, boxes that do not overlap, and owners
// that follow the entities, not their input order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <set>
#include <stdexcept>
#include <vector>

#include "parallel/rcb.hpp"

namespace {

using crater::Index;
using crater::Real;
using crater::Vec;
using crater::parallel::Decomposition;
using crater::parallel::rcb;

template <int D>
Decomposition cut(const std::vector<Vec<D>>& x, const std::vector<Real>& w, int ranks) {
  return rcb<D>(std::span<const Vec<D>>(x), std::span<const Real>(w), ranks);
}

// The exact share of a rank of r among R at each level of the bisection: floor/ceil halving
// gives rank k the fraction 1/R of the total only when every cut lands exactly; a cut can miss
// its share by at most half an entity's weight, and the misses of the levels above a rank add
// up, so a rank's weight is within (levels) x max weight of total / R.
int levels(int ranks) {
  int l = 0;
  while ((1 << l) < ranks)
    ++l;
  return l;
}

template <int D>
std::vector<Vec<D>> random_points(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<Real> u(0.0, 1.0);
  std::vector<Vec<D>> x(n);
  for (auto& p : x)
    for (int a = 0; a < D; ++a)
      p[a] = u(rng) * (a == 1 ? 2.0 : 1.0);  // a box twice as tall as wide
  return x;
}

template <int D>
void expect_disjoint_boxes(const std::vector<Vec<D>>& x, const Decomposition& d, int ranks) {
  // Each rank's box of its entities; two boxes may share a face (entities on the cut plane) but
  // no interior: on some axis one ends where the other begins, or before.
  std::vector<Vec<D>> lo(static_cast<std::size_t>(ranks), Vec<D>::Constant(1e300));
  std::vector<Vec<D>> hi(static_cast<std::size_t>(ranks), Vec<D>::Constant(-1e300));
  for (std::size_t i = 0; i < x.size(); ++i) {
    const auto r = static_cast<std::size_t>(d.owner[i]);
    lo[r] = lo[r].cwiseMin(x[i]);
    hi[r] = hi[r].cwiseMax(x[i]);
  }
  for (int a = 0; a < ranks; ++a)
    for (int b = a + 1; b < ranks; ++b) {
      bool apart = false;
      for (int k = 0; k < D; ++k)
        apart = apart || hi[static_cast<std::size_t>(a)][k] <= lo[static_cast<std::size_t>(b)][k] ||
                hi[static_cast<std::size_t>(b)][k] <= lo[static_cast<std::size_t>(a)][k];
      EXPECT_TRUE(apart) << "ranks " << a << " and " << b << " overlap";
    }
}

TEST(Rcb, LatticeOfEqualWeightsSplitsIntoEqualBlocks) {
  std::vector<Vec<2>> x;
  for (int j = 0; j < 20; ++j)
    for (int i = 0; i < 10; ++i)
      x.emplace_back(i, j);
  const std::vector<Real> w(x.size(), 1.0);
  const Decomposition d = cut<2>(x, w, 4);
  for (int r = 0; r < 4; ++r) {
    EXPECT_EQ(d.count[static_cast<std::size_t>(r)], 50);
    EXPECT_EQ(d.weight[static_cast<std::size_t>(r)], 50.0);
  }
  expect_disjoint_boxes<2>(x, d, 4);
  // The first cut is across the longer side (y, 20 rows): ranks 0-1 hold rows 0-9.
  for (std::size_t i = 0; i < x.size(); ++i)
    EXPECT_EQ(d.owner[i] < 2, x[i].y() < 10) << "entity " << i;
}

TEST(Rcb, EveryRankCountBalancesTheWeightIn2DAnd3D) {
  for (const int ranks : {1, 2, 3, 5, 7, 8, 12, 64}) {
    SCOPED_TRACE(ranks);
    const auto x2 = random_points<2>(5000, 11);
    const auto x3 = random_points<3>(5000, 12);
    std::mt19937_64 rng(13);
    std::uniform_real_distribution<Real> u(0.5, 3.0);  // SPH, FEM and DEM costs differ
    std::vector<Real> w(5000);
    for (Real& v : w)
      v = u(rng);
    const Real total = std::accumulate(w.begin(), w.end(), 0.0);
    const Real w_max = *std::max_element(w.begin(), w.end());
    for (const Decomposition& d : {cut<2>(x2, w, ranks), cut<3>(x3, w, ranks)}) {
      ASSERT_EQ(d.owner.size(), 5000u);
      Index owned = 0;
      for (int r = 0; r < ranks; ++r) {
        owned += d.count[static_cast<std::size_t>(r)];
        EXPECT_GT(d.count[static_cast<std::size_t>(r)], 0);
        EXPECT_NEAR(d.weight[static_cast<std::size_t>(r)], total / ranks,
                    levels(ranks) * w_max + 1e-9 * total);
      }
      EXPECT_EQ(owned, 5000);
      for (const int o : d.owner) {
        EXPECT_GE(o, 0);
        EXPECT_LT(o, ranks);
      }
    }
    expect_disjoint_boxes<2>(x2, cut<2>(x2, w, ranks), ranks);
    expect_disjoint_boxes<3>(x3, cut<3>(x3, w, ranks), ranks);
  }
}

TEST(Rcb, HeavyEntitiesGetSmallerBoxes) {
  // The left half's entities cost three times the right half's: the 2-rank cut moves left of
  // the middle, to where the weight is halved (after 40 of the 120 columns).
  std::vector<Vec<2>> x;
  std::vector<Real> w;
  for (int j = 0; j < 10; ++j)
    for (int i = 0; i < 120; ++i) {
      x.emplace_back((i + 0.5) / 120.0 * 4.0, j * 0.1);  // 4 wide, 1 tall: cut across x
      w.push_back(i < 60 ? 3.0 : 1.0);
    }
  const Decomposition d = cut<2>(x, w, 2);
  // Total 10 x (60 x 3 + 60) = 2,400; half is 1,200 = 10 rows x 40 columns of weight 3.
  EXPECT_DOUBLE_EQ(d.weight[0], 1200.0);
  EXPECT_EQ(d.count[0], 400);
  EXPECT_EQ(d.count[1], 800);
}

TEST(Rcb, OwnersFollowTheEntitiesNotTheirInputOrder) {
  const auto x = random_points<3>(3000, 21);
  std::vector<Real> w(x.size());
  for (std::size_t i = 0; i < w.size(); ++i)
    w[i] = 1.0 + static_cast<Real>(i % 7);
  std::vector<std::size_t> perm(x.size());
  std::iota(perm.begin(), perm.end(), 0u);
  std::shuffle(perm.begin(), perm.end(), std::mt19937_64(22));
  std::vector<Vec<3>> xp(x.size());
  std::vector<Real> wp(x.size());
  for (std::size_t k = 0; k < perm.size(); ++k) {
    xp[k] = x[perm[k]];
    wp[k] = w[perm[k]];
  }
  const Decomposition a = cut<3>(x, w, 6), b = cut<3>(xp, wp, 6);
  for (std::size_t k = 0; k < perm.size(); ++k)
    ASSERT_EQ(b.owner[k], a.owner[perm[k]]) << "entity " << perm[k];
  for (int r = 0; r < 6; ++r)  // the same sets, summed in another order: equal to rounding
    EXPECT_NEAR(b.weight[static_cast<std::size_t>(r)], a.weight[static_cast<std::size_t>(r)],
                1e-12 * a.weight[static_cast<std::size_t>(r)]);
}

TEST(Rcb, CoincidentEntitiesSplitByIndex) {
  const std::vector<Vec<2>> x(9, Vec<2>(0.25, 0.5));
  const std::vector<Real> w(9, 1.0);
  const Decomposition d = cut<2>(x, w, 3);
  EXPECT_EQ(d.owner, (std::vector<int>{0, 0, 0, 1, 1, 1, 2, 2, 2}));
}

TEST(Rcb, FewerEntitiesThanRanksAndBadInput) {
  const std::vector<Vec<2>> x{Vec<2>(0, 0), Vec<2>(1, 0)};
  const std::vector<Real> w{1.0, 1.0};
  const Decomposition d = cut<2>(x, w, 4);
  EXPECT_NE(d.owner[0], d.owner[1]);
  EXPECT_EQ(std::accumulate(d.count.begin(), d.count.end(), Index{0}), 2);
  EXPECT_THROW(cut<2>(x, w, 0), std::invalid_argument);
  EXPECT_THROW(cut<2>(x, std::vector<Real>{1.0}, 2), std::invalid_argument);
  EXPECT_THROW(cut<2>(x, std::vector<Real>{1.0, -1.0}, 2), std::invalid_argument);
  EXPECT_THROW(cut<2>(x, std::vector<Real>{1.0, NAN}, 2), std::invalid_argument);
}

// The tree of the cuts gives every entity the rank RCB gave it (random coordinates: no entity
// sits on a cut), and any other point the rank whose box holds it: points drawn anywhere in the
// set's box fall in the box of their tree rank's entities grown by the gaps at the cuts.
template <int D>
void tree_matches(int ranks) {
  const auto x = random_points<D>(3000, 11u + static_cast<unsigned>(ranks));
  std::vector<Real> w(x.size());
  for (std::size_t i = 0; i < w.size(); ++i)
    w[i] = 1.0 + static_cast<Real>(i % 7);
  const Decomposition d = cut<D>(x, w, ranks);
  const auto tree =
      crater::parallel::rcb_tree<D>(std::span<const Vec<D>>(x), std::span<const Real>(w), ranks);
  const int nodes_expected = 2 * ranks - 1;  // a full binary tree with a leaf per rank
  EXPECT_EQ(static_cast<int>(tree.nodes.size()), nodes_expected) << ranks << " ranks";
  for (std::size_t i = 0; i < x.size(); ++i)
    ASSERT_EQ(tree.owner(x[i]), d.owner[i]) << "entity " << i << ", " << ranks << " ranks";
  // Every rank is some leaf's, once.
  std::vector<int> leaves;
  for (const auto& n : tree.nodes)
    if (n.axis < 0) leaves.push_back(n.rank);
  std::sort(leaves.begin(), leaves.end());
  std::vector<int> all(static_cast<std::size_t>(ranks));
  std::iota(all.begin(), all.end(), 0);
  EXPECT_EQ(leaves, all);
}

TEST(Rcb, TreeGivesTheOwnersOfRcb) {
  for (int ranks : {1, 2, 3, 4, 5, 7, 8}) {
    tree_matches<2>(ranks);
    tree_matches<3>(ranks);
  }
}

// A square bed cut once across x; a grain thrown a little beyond its side makes the box 2 %
// longer in y. Cuts made afresh swap to y and move about half the bed to the other rank; made
// again from the cuts before, they keep x (parallel::kKeepAxis) and move none. A box 20 % longer
// in y is cut across y either way.
TEST(Rcb, CutsMadeAgainKeepTheirAxisWhileTheBoxAllows) {
  using crater::parallel::rcb_tree;
  using crater::parallel::RcbTree;
  std::vector<Vec<2>> x;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j)
      x.push_back({(i + 0.5) / 40.0, (j + 0.5) / 40.0});
  std::vector<Real> w(x.size(), 1.0);
  const RcbTree<2> first = rcb_tree<2>(x, w, 2);
  ASSERT_EQ(first.nodes[0].axis, 0);  // the lowest axis on a tie
  auto moved = [&](const RcbTree<2>& a, const RcbTree<2>& b) {
    int n = 0;
    for (const auto& p : x)
      n += a.owner(p) != b.owner(p);
    return n;
  };
  for (const auto& [stretch, axis] : {std::pair{1.02, 0}, std::pair{1.2, 1}}) {
    std::vector<Vec<2>> y = x;
    y.push_back({0.5, stretch});  // the thrown grain
    std::vector<Real> wy(y.size(), 1.0);
    const RcbTree<2> afresh = rcb_tree<2>(y, wy, 2);
    const RcbTree<2> again = rcb_tree<2>(y, wy, 2, &first);
    EXPECT_EQ(afresh.nodes[0].axis, 1) << stretch;
    EXPECT_GT(moved(first, afresh), 700) << stretch;
    EXPECT_EQ(again.nodes[0].axis, axis) << stretch;
    if (axis == 0) {
      EXPECT_LE(moved(first, again), 40) << stretch;
    }
  }
  // More ranks: every node keeps its own axis (the tree's shape is the rank count's).
  const RcbTree<2> four = rcb_tree<2>(x, w, 4);
  std::vector<Vec<2>> y = x;
  y.push_back({0.5, 1.02});
  std::vector<Real> wy(y.size(), 1.0);
  const RcbTree<2> again = rcb_tree<2>(y, wy, 4, &four);
  ASSERT_EQ(again.nodes.size(), four.nodes.size());
  for (std::size_t k = 0; k < four.nodes.size(); ++k)
    EXPECT_EQ(again.nodes[k].axis, four.nodes[k].axis) << k;
}

}  // namespace
