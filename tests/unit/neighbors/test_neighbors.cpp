// Cell-list neighbour search against brute force, edge cases, and thread-count independence.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "neighbors/cell_grid.hpp"
#include "neighbors/neighbor_list.hpp"
#include "neighbors/pair_radius_list.hpp"

namespace crater::neighbors {
namespace {

using Rows = std::vector<std::vector<Index>>;

// Same summation order as the library, so pairs at exactly the radius compare alike.
template <int D>
Real dist2(const Vec<D>& p, const Vec<D>& q) {
  Real s = 0;
  for (int k = 0; k < D; ++k) {
    s += (p[k] - q[k]) * (p[k] - q[k]);
  }
  return s;
}

template <int D>
Rows brute_self(const std::vector<Vec<D>>& x, Real r, Pairs mode) {
  Rows rows(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    for (std::size_t j = 0; j < x.size(); ++j) {
      if (j == i || (mode == Pairs::Half && j < i)) continue;
      if (dist2<D>(x[i], x[j]) <= r * r) rows[i].push_back(static_cast<Index>(j));
    }
  }
  return rows;
}

// Rows restricted to j > i.
Rows only_greater(const Rows& rows) {
  Rows out(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    for (Index j : rows[i]) {
      if (j > static_cast<Index>(i)) {
        out[i].push_back(j);
      }
    }
  }
  return out;
}

template <int D>
Rows brute_cross(const std::vector<Vec<D>>& a, const std::vector<Vec<D>>& b, Real r) {
  Rows rows(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::size_t j = 0; j < b.size(); ++j) {
      if (dist2<D>(a[i], b[j]) <= r * r) rows[i].push_back(static_cast<Index>(j));
    }
  }
  return rows;
}

// Checks the CSR invariants and returns the rows.
Rows rows_of(const NeighborList& nl) {
  EXPECT_GE(nl.offsets.size(), 1u);
  EXPECT_EQ(nl.offsets.front(), 0);
  EXPECT_EQ(nl.offsets.back(), nl.total_pairs());
  Rows rows(static_cast<std::size_t>(nl.size()));
  for (Index i = 0; i < nl.size(); ++i) {
    const auto row = nl.of(i);
    rows[static_cast<std::size_t>(i)].assign(row.begin(), row.end());
    EXPECT_TRUE(std::adjacent_find(row.begin(), row.end(), std::greater_equal<Index>()) ==
                row.end())
        << "row " << i << " is not strictly ascending";
  }
  return rows;
}

template <int D>
std::span<const Vec<D>> sp(const std::vector<Vec<D>>& v) {
  return {v.data(), v.size()};
}

template <int D>
Rows cell_self(const std::vector<Vec<D>>& x, Real r, Pairs mode) {
  NeighborList nl;
  build_neighbor_list<D>(sp(x), r, mode, nl);
  EXPECT_EQ(nl.size(), static_cast<Index>(x.size()));
  return rows_of(nl);
}

template <int D>
std::vector<Vec<D>> random_points(std::size_t n, Real lo, Real hi, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<Real> u(lo, hi);
  std::vector<Vec<D>> x(n);
  for (auto& p : x) {
    for (int k = 0; k < D; ++k) {
      p[k] = u(rng);
    }
  }
  return x;
}

// x re-ordered by cell_sort_order, as a part does before building lists.
template <int D>
std::vector<Vec<D>> resorted(const std::vector<Vec<D>>& x, Real cell_size) {
  const std::vector<Index> order = cell_sort_order<D>(sp(x), cell_size);
  std::vector<Vec<D>> y(x.size());
  for (std::size_t k = 0; k < x.size(); ++k) {
    y[k] = x[static_cast<std::size_t>(order[k])];
  }
  return y;
}

std::size_t total(const Rows& rows) {
  std::size_t t = 0;
  for (const auto& r : rows) {
    t += r.size();
  }
  return t;
}

template <int D>
void check_random_against_brute_force() {
  std::uint64_t seed = 1234 + D;
  // Sizes and radii keep the brute force affordable in Debug and sanitizer builds too.
  for (std::size_t n : {1u, 2u, 7u, 100u, 800u, 2500u}) {
    for (Real r : {0.013, 0.05, 0.2, 3.0}) {
      if (n > 800 && r > 0.1) continue;
      const auto random_order = random_points<D>(n, -0.7, 0.6, seed++);
      // Random order takes the sort-per-cell path; re-sorted by cell, the in-place path.
      for (const auto& x : {random_order, resorted<D>(random_order, r)}) {
        SCOPED_TRACE(::testing::Message() << "D=" << D << " n=" << n << " r=" << r);
        const Rows full = brute_self<D>(x, r, Pairs::Full);
        EXPECT_EQ(cell_self<D>(x, r, Pairs::Full), full);
        EXPECT_EQ(cell_self<D>(x, r, Pairs::Half), only_greater(full));
      }
    }
  }
}

TEST(NeighborList, MatchesBruteForceRandom2D) {
  check_random_against_brute_force<2>();
}
TEST(NeighborList, MatchesBruteForceRandom3D) {
  check_random_against_brute_force<3>();
}

// Sanity of the test data itself: the random sets above do have neighbours.
TEST(NeighborList, RandomSetHasNonTrivialLists) {
  const auto x = random_points<2>(1000, 0, 1, 7);
  const Rows rows = cell_self<2>(x, 0.05, Pairs::Full);
  // Expected about 1000 * pi * 0.05^2 * 1000 = 7850 entries, minus boundary losses.
  EXPECT_GT(total(rows), 6000u);
  EXPECT_LT(total(rows), 9000u);
}

// Lattice spacing == radius == an exactly representable number: neighbours sit exactly at the
// radius and exactly on cell faces.
TEST(NeighborList, LatticeAtExactRadius2D) {
  const Real h = 0.25;
  const int m = 20;
  std::vector<Vec<2>> x;
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) {
      x.push_back(Vec<2>(i * h, j * h));
    }
  }
  const Rows rows = cell_self<2>(x, h, Pairs::Full);
  EXPECT_EQ(rows, brute_self<2>(x, h, Pairs::Full));
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) {
      const int boundary = (i == 0 || i == m - 1) + (j == 0 || j == m - 1);
      EXPECT_EQ(rows[static_cast<std::size_t>(i * m + j)].size(),
                static_cast<std::size_t>(4 - boundary));
    }
  }
  // Interior point: the four axis neighbours, ascending.
  const Index c = 5 * m + 7;
  EXPECT_EQ(rows[static_cast<std::size_t>(c)], (std::vector<Index>{c - m, c - 1, c + 1, c + m}));
}

TEST(NeighborList, LatticeAtExactRadius3D) {
  const Real h = 0.5;
  const int m = 9;
  std::vector<Vec<3>> x;
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) {
      for (int k = 0; k < m; ++k) {
        x.push_back(Vec<3>(i * h - 2.0, j * h + 1.0, k * h));
      }
    }
  }
  const Rows rows = cell_self<3>(x, h, Pairs::Full);
  EXPECT_EQ(rows, brute_self<3>(x, h, Pairs::Full));
  const std::size_t interior = static_cast<std::size_t>((4 * m + 4) * m + 4);
  EXPECT_EQ(rows[interior].size(), 6u);
  // Radius just past the face diagonal picks up the 12 edge neighbours too.
  const Rows wider = cell_self<3>(x, h * std::sqrt(2.0) * 1.0000001, Pairs::Full);
  EXPECT_EQ(wider[interior].size(), 18u);
}

// Non-representable spacing: neighbours at "the radius" fall either side by rounding, and the
// cell list must agree with brute force on each.
TEST(NeighborList, LatticeAtInexactRadius) {
  const Real h = 0.1;
  std::vector<Vec<2>> x;
  for (int i = 0; i < 30; ++i) {
    for (int j = 0; j < 30; ++j) {
      x.push_back(Vec<2>(i * h, j * h));
    }
  }
  EXPECT_EQ(cell_self<2>(x, h, Pairs::Full), brute_self<2>(x, h, Pairs::Full));
  EXPECT_EQ(cell_self<2>(x, 2 * h, Pairs::Half), brute_self<2>(x, 2 * h, Pairs::Half));
}

// Random points whose coordinates are multiples of the cell size, with repeats.
TEST(NeighborList, PointsOnCellFaces) {
  std::mt19937_64 rng(99);
  std::uniform_int_distribution<int> u(-6, 6);
  for (Real r : {0.5, 0.375, 1.0}) {
    std::vector<Vec<3>> x(800);
    for (auto& p : x) {
      p = Vec<3>(u(rng) * r, u(rng) * r, u(rng) * r);
    }
    EXPECT_EQ(cell_self<3>(x, r, Pairs::Full), brute_self<3>(x, r, Pairs::Full));
    std::vector<Vec<2>> y(800);
    for (auto& p : y) {
      p = Vec<2>(u(rng) * r, u(rng) * r);
    }
    EXPECT_EQ(cell_self<2>(y, r, Pairs::Half), brute_self<2>(y, r, Pairs::Half));
  }
}

// Far from the origin, coordinates carry large absolute rounding.
TEST(NeighborList, OffsetFromOrigin) {
  auto x = random_points<2>(3000, 0, 1, 31);
  for (auto& p : x) {
    p += Vec<2>(1e6, -3e5);
  }
  EXPECT_EQ(cell_self<2>(x, 0.03, Pairs::Full), brute_self<2>(x, 0.03, Pairs::Full));
}

TEST(NeighborList, SinglePoint) {
  const std::vector<Vec<2>> x{Vec<2>(0.3, -1.2)};
  NeighborList nl;
  build_neighbor_list<2>(sp(x), 1.0, Pairs::Full, nl);
  ASSERT_EQ(nl.size(), 1);
  EXPECT_TRUE(nl.of(0).empty());
  EXPECT_EQ(nl.total_pairs(), 0);
}

TEST(NeighborList, EmptySet) {
  const std::vector<Vec<3>> x;
  NeighborList nl;
  nl.offsets = {0, 1, 2};  // stale content must go
  nl.indices = {5, 6};
  build_neighbor_list<3>(sp(x), 1.0, Pairs::Half, nl);
  EXPECT_EQ(nl.size(), 0);
  EXPECT_EQ(nl.offsets, std::vector<Index>{0});
  EXPECT_EQ(nl.total_pairs(), 0);
}

TEST(NeighborList, AllPointsInOneCell) {
  const auto x = random_points<3>(50, 2.0, 2.1, 5);  // box diagonal 0.17 < radius
  const Rows rows = cell_self<3>(x, 0.5, Pairs::Full);
  for (std::size_t i = 0; i < x.size(); ++i) {
    std::vector<Index> all;
    for (std::size_t j = 0; j < x.size(); ++j) {
      if (j != i) all.push_back(static_cast<Index>(j));
    }
    EXPECT_EQ(rows[i], all);
  }
}

TEST(NeighborList, AllPointsCoincident) {
  const std::vector<Vec<2>> x(40, Vec<2>(1.5, 1.5));
  const Rows full = cell_self<2>(x, 1e-3, Pairs::Full);
  const Rows half = cell_self<2>(x, 1e-3, Pairs::Half);
  EXPECT_EQ(total(full), 40u * 39u);
  EXPECT_EQ(total(half), 40u * 39u / 2u);
  EXPECT_EQ(full[0].front(), 1);
  EXPECT_EQ(full[39].back(), 38);
  EXPECT_EQ(half[0].size(), 39u);
  EXPECT_TRUE(half[39].empty());
}

TEST(NeighborList, HalfIsFullFilteredToGreaterIndices) {
  const auto x = random_points<3>(3000, 0, 1, 77);
  const Rows full = cell_self<3>(x, 0.08, Pairs::Full);
  const Rows half = cell_self<3>(x, 0.08, Pairs::Half);
  ASSERT_EQ(full.size(), half.size());
  std::size_t kept = 0;
  for (std::size_t i = 0; i < full.size(); ++i) {
    std::vector<Index> filtered;
    for (Index j : full[i]) {
      if (j > static_cast<Index>(i)) filtered.push_back(j);
    }
    EXPECT_EQ(half[i], filtered) << "row " << i;
    kept += filtered.size();
  }
  EXPECT_EQ(2 * kept, total(full));  // symmetry of the full list
  EXPECT_GT(kept, 0u);
}

// A dense cluster plus far outliers: the cell cap makes cells coarse, results stay exact.
TEST(NeighborList, FarOutliers) {
  auto x = random_points<2>(2000, 0, 1, 3);
  x.push_back(Vec<2>(1e5, -1e5));
  x.push_back(Vec<2>(1e5 + 0.01, -1e5));
  x.push_back(Vec<2>(-3e4, 2e3));
  const Rows rows = cell_self<2>(x, 0.04, Pairs::Full);
  EXPECT_EQ(rows, brute_self<2>(x, 0.04, Pairs::Full));
  EXPECT_EQ(rows[2000], std::vector<Index>{2001});
}

TEST(NeighborList, ReusesStorage) {
  NeighborList nl;
  const auto big = random_points<2>(5000, 0, 1, 11);
  build_neighbor_list<2>(sp(big), 0.03, Pairs::Full, nl);
  const Index* offsets_data = nl.offsets.data();
  const Index* indices_data = nl.indices.data();
  const auto small = random_points<2>(3000, 0, 1, 12);
  build_neighbor_list<2>(sp(small), 0.03, Pairs::Full, nl);
  EXPECT_EQ(nl.offsets.data(), offsets_data);
  EXPECT_EQ(nl.indices.data(), indices_data);
  EXPECT_EQ(rows_of(nl), brute_self<2>(small, 0.03, Pairs::Full));
}

TEST(NeighborList, RejectsBadInput) {
  std::vector<Vec<2>> x = random_points<2>(10, 0, 1, 1);
  NeighborList nl;
  const Real nan = std::numeric_limits<Real>::quiet_NaN();
  const Real inf = std::numeric_limits<Real>::infinity();
  for (Real r : {0.0, -1.0, nan, inf}) {
    EXPECT_THROW(build_neighbor_list<2>(sp(x), r, Pairs::Full, nl), std::invalid_argument);
    EXPECT_THROW(build_cross_list<2>(sp(x), sp(x), r, nl), std::invalid_argument);
  }
  x[7] = Vec<2>(0.5, nan);
  try {
    build_neighbor_list<2>(sp(x), 0.1, Pairs::Full, nl);
    ADD_FAILURE() << "no exception for a NaN coordinate";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("point 7"), std::string::npos) << e.what();
  }
  const std::vector<Vec<2>> good = random_points<2>(10, 0, 1, 2);
  x[7] = Vec<2>(inf, 0.5);
  EXPECT_THROW(build_cross_list<2>(sp(x), sp(good), 0.1, nl), std::invalid_argument);
  EXPECT_THROW(build_cross_list<2>(sp(good), sp(x), 0.1, nl), std::invalid_argument);
  // A non-finite query point is rejected even when there is nothing to search.
  const std::vector<Vec<2>> none;
  EXPECT_THROW(build_cross_list<2>(sp(x), sp(none), 0.1, nl), std::invalid_argument);
}

template <int D>
void check_cross_against_brute_force() {
  std::uint64_t seed = 500 + D;
  for (std::size_t na : {1u, 60u, 1500u}) {
    for (std::size_t nb : {1u, 80u, 2500u}) {
      for (Real r : {0.02, 0.1, 5.0}) {
        if (na * nb > 1000000 && r > 1) continue;  // all-pairs lists of this size are slow
        SCOPED_TRACE(::testing::Message()
                     << "D=" << D << " na=" << na << " nb=" << nb << " r=" << r);
        // a extends well beyond b's box, so some queries fall outside the grid.
        const auto a = random_points<D>(na, -1.5, 1.5, seed++);
        const auto b_random = random_points<D>(nb, -0.5, 0.5, seed++);
        for (const auto& b : {b_random, resorted<D>(b_random, r)}) {
          NeighborList nl;
          build_cross_list<D>(sp(a), sp(b), r, nl);
          ASSERT_EQ(nl.size(), static_cast<Index>(na));
          EXPECT_EQ(rows_of(nl), brute_cross<D>(a, b, r));
        }
      }
    }
  }
}

// The other way round: the candidates spread far beyond the queries (a charge in a soil bed),
// so that the search runs on subsets of both sets and maps the indices back.
template <int D>
void check_small_queries_in_a_large_bed() {
  std::uint64_t seed = 900 + D;
  for (Real r : {0.01, 0.05, 0.3}) {
    SCOPED_TRACE(::testing::Message() << "D=" << D << " r=" << r);
    const auto a = random_points<D>(300, 0.1, 0.3, seed++);
    const auto b = random_points<D>(6000, -1.0, 1.0, seed++);
    NeighborList nl;
    build_cross_list<D>(sp(a), sp(b), r, nl);
    ASSERT_EQ(nl.size(), 300);
    EXPECT_EQ(rows_of(nl), brute_cross<D>(a, b, r));
    NeighborList back;
    build_cross_list<D>(sp(b), sp(a), r, back);
    ASSERT_EQ(back.size(), 6000);
    EXPECT_EQ(rows_of(back), brute_cross<D>(b, a, r));
  }
}

TEST(NeighborCrossList, SmallQueriesInALargeBed) {
  check_small_queries_in_a_large_bed<2>();
  check_small_queries_in_a_large_bed<3>();
}

TEST(NeighborCrossList, MatchesBruteForce2D) {
  check_cross_against_brute_force<2>();
}
TEST(NeighborCrossList, MatchesBruteForce3D) {
  check_cross_against_brute_force<3>();
}

TEST(NeighborCrossList, EmptySets) {
  const auto pts = random_points<3>(20, 0, 1, 8);
  const std::vector<Vec<3>> none;
  NeighborList nl;
  build_cross_list<3>(sp(none), sp(pts), 0.5, nl);
  EXPECT_EQ(nl.size(), 0);
  EXPECT_EQ(nl.total_pairs(), 0);
  build_cross_list<3>(sp(pts), sp(none), 0.5, nl);
  EXPECT_EQ(nl.size(), 20);
  EXPECT_EQ(nl.total_pairs(), 0);
  for (Index i = 0; i < 20; ++i) {
    EXPECT_TRUE(nl.of(i).empty());
  }
}

// A set against itself: the cross list is the full list plus i itself.
TEST(NeighborCrossList, SelfCrossIsFullPlusSelf) {
  const auto x = random_points<2>(2000, 0, 1, 21);
  NeighborList cross;
  build_cross_list<2>(sp(x), sp(x), 0.04, cross);
  const Rows full = cell_self<2>(x, 0.04, Pairs::Full);
  const Rows rows = rows_of(cross);
  for (std::size_t i = 0; i < x.size(); ++i) {
    std::vector<Index> with_self = full[i];
    with_self.insert(std::lower_bound(with_self.begin(), with_self.end(), Index(i)), Index(i));
    EXPECT_EQ(rows[i], with_self);
  }
}

// Runs f with n OpenMP threads and restores the previous setting.
template <class F>
void with_threads(int n, F&& f) {
  const int before = omp_get_max_threads();
  omp_set_num_threads(n);
  f();
  omp_set_num_threads(before);
}

TEST(NeighborList, SameResultForOneAndTwoThreads) {
  // Large enough to take the parallel path (and several dynamic chunks).
  const auto x2 = random_points<2>(60000, 0, 1, 41);
  const auto x3 = random_points<3>(40000, 0, 1, 42);
  const auto a3 = random_points<3>(30000, -0.2, 1.2, 43);
  const auto s3 = resorted<3>(x3, 0.04);
  NeighborList l1, l2, h1, h2, c1, c2, d1, d2, e1, e2;
  std::vector<Index> o1, o2;
  with_threads(1, [&] {
    build_neighbor_list<3>(sp(s3), 0.04, Pairs::Half, e1);
    build_neighbor_list<2>(sp(x2), 0.01, Pairs::Full, l1);
    build_neighbor_list<3>(sp(x3), 0.04, Pairs::Half, h1);
    build_cross_list<3>(sp(a3), sp(x3), 0.04, c1);
    build_neighbor_list<3>(sp(x3), 0.04, Pairs::Full, d1);
    o1 = cell_sort_order<3>(sp(x3), 0.04);
  });
  with_threads(2, [&] {
    build_neighbor_list<3>(sp(s3), 0.04, Pairs::Half, e2);
    build_neighbor_list<2>(sp(x2), 0.01, Pairs::Full, l2);
    build_neighbor_list<3>(sp(x3), 0.04, Pairs::Half, h2);
    build_cross_list<3>(sp(a3), sp(x3), 0.04, c2);
    build_neighbor_list<3>(sp(x3), 0.04, Pairs::Full, d2);
    o2 = cell_sort_order<3>(sp(x3), 0.04);
  });
  EXPECT_GT(l1.total_pairs(), 60000);
  EXPECT_GT(h1.total_pairs(), 40000);
  EXPECT_EQ(l1.offsets, l2.offsets);
  EXPECT_EQ(l1.indices, l2.indices);
  EXPECT_EQ(h1.offsets, h2.offsets);
  EXPECT_EQ(h1.indices, h2.indices);
  EXPECT_EQ(c1.offsets, c2.offsets);
  EXPECT_EQ(c1.indices, c2.indices);
  EXPECT_EQ(d1.offsets, d2.offsets);
  EXPECT_EQ(d1.indices, d2.indices);
  EXPECT_EQ(o1, o2);
  EXPECT_EQ(e1.offsets, e2.offsets);
  EXPECT_EQ(e1.indices, e2.indices);
  EXPECT_EQ(e1.total_pairs(), h1.total_pairs());
  // Sampled rows of the large 2D set against brute force (the parallel path's correctness).
  const Rows rows = rows_of(l2);
  for (std::size_t i = 0; i < x2.size(); i += 397) {
    std::vector<Index> expected;
    for (std::size_t j = 0; j < x2.size(); ++j) {
      if (j != i && dist2<2>(x2[i], x2[j]) <= 0.01 * 0.01) expected.push_back(Index(j));
    }
    EXPECT_EQ(rows[i], expected) << "row " << i;
  }
  // Likewise for the cross list on the parallel path.
  const Rows cross = rows_of(c2);
  for (std::size_t i = 0; i < a3.size(); i += 211) {
    std::vector<Index> expected;
    for (std::size_t j = 0; j < x3.size(); ++j) {
      if (dist2<3>(a3[i], x3[j]) <= 0.04 * 0.04) expected.push_back(Index(j));
    }
    EXPECT_EQ(cross[i], expected) << "cross row " << i;
  }
}

template <int D>
void check_sort_order(std::size_t n, Real cell_size, Real lo, Real hi, std::uint64_t seed) {
  const auto x = random_points<D>(n, lo, hi, seed);
  const std::vector<Index> order = cell_sort_order<D>(sp(x), cell_size);
  ASSERT_EQ(order.size(), n);
  std::vector<Index> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  std::vector<Index> iota(n);
  std::iota(iota.begin(), iota.end(), Index(0));
  EXPECT_EQ(sorted, iota) << "not a permutation";

  const GridSpec<D> grid = make_grid_spec<D>(sp(x), cell_size);
  EXPECT_GT(grid.cell_count(), 1);
  Index changes = 0;
  for (std::size_t s = 1; s < n; ++s) {
    const Index cp = grid.cell_index(x[static_cast<std::size_t>(order[s - 1])]);
    const Index cs = grid.cell_index(x[static_cast<std::size_t>(order[s])]);
    ASSERT_LE(cp, cs) << "cells not ascending at " << s;
    if (cp == cs) {
      ASSERT_LT(order[s - 1], order[s]) << "not stable within a cell at " << s;
    } else {
      ++changes;
    }
  }
  EXPECT_GT(changes, 0);
}

// --- Lists with a radius per point: pair (i, j) when within max(reach_i, reach_j).

template <int D>
Rows brute_pair_radius(const std::vector<Vec<D>>& x, const std::vector<Real>& reach) {
  Rows rows(x.size());
  for (std::size_t i = 0; i < x.size(); ++i)
    for (std::size_t j = 0; j < x.size(); ++j) {
      const Real r = std::max(reach[i], reach[j]);
      if (j != i && dist2<D>(x[i], x[j]) <= r * r) rows[i].push_back(static_cast<Index>(j));
    }
  return rows;
}

template <int D>
Rows pair_radius_rows(const std::vector<Vec<D>>& x, const std::vector<Real>& reach) {
  NeighborList nl;
  std::vector<NeighborList> scratch;
  build_pair_radius_list<D>(sp(x), std::span<const Real>(reach), nl, scratch);
  EXPECT_EQ(nl.size(), static_cast<Index>(x.size()));
  return rows_of(nl);
}

// Radii spread over 1:spread (several levels), the largest ones few, as hot SPH particles are.
template <int D>
void check_pair_radius_against_brute_force() {
  std::uint64_t seed = 77 + D;
  for (std::size_t n : {1u, 2u, 9u, 300u, 1500u}) {
    for (Real spread : {1.0, 1.5, 8.0, 40.0}) {
      const auto x = random_points<D>(n, -0.5, 0.5, seed++);
      std::mt19937_64 rng(seed++);
      std::uniform_real_distribution<Real> u(0, 1);
      std::vector<Real> reach(n);
      for (auto& r : reach)
        r = 0.02 * std::pow(spread, u(rng) * u(rng) * u(rng));
      SCOPED_TRACE(::testing::Message() << "D=" << D << " n=" << n << " spread=" << spread);
      const Rows expected = brute_pair_radius<D>(x, reach);
      EXPECT_EQ(pair_radius_rows<D>(x, reach), expected);
      EXPECT_EQ(pair_radius_rows<D>(resorted<D>(x, 0.04), reach),
                brute_pair_radius<D>(resorted<D>(x, 0.04), reach));
    }
  }
}

TEST(PairRadiusList, MatchesBruteForce2D) {
  check_pair_radius_against_brute_force<2>();
}
TEST(PairRadiusList, MatchesBruteForce3D) {
  check_pair_radius_against_brute_force<3>();
}

// Two sets (SPH's fluid and its mirror images): for each a, the b within the larger radius.
template <int D>
void check_cross_radius_against_brute_force() {
  std::uint64_t seed = 91 + D;
  for (auto [na, nb] : {std::pair<std::size_t, std::size_t>{1, 1}, {7, 300}, {1200, 500}}) {
    for (Real spread : {1.0, 1.5, 8.0, 40.0}) {
      const auto a = random_points<D>(na, -0.5, 0.5, seed++);
      const auto b = random_points<D>(nb, -0.3, 0.6, seed++);
      std::mt19937_64 rng(seed++);
      std::uniform_real_distribution<Real> u(0, 1);
      std::vector<Real> ra(na), rb(nb);
      for (auto& r : ra)
        r = 0.02 * std::pow(spread, u(rng) * u(rng) * u(rng));
      for (auto& r : rb)
        r = 0.02 * std::pow(spread, u(rng) * u(rng));
      Rows expected(na);
      for (std::size_t i = 0; i < na; ++i)
        for (std::size_t j = 0; j < nb; ++j) {
          const Real r = std::max(ra[i], rb[j]);
          if (dist2<D>(a[i], b[j]) <= r * r) expected[i].push_back(static_cast<Index>(j));
        }
      NeighborList nl;
      std::vector<NeighborList> scratch;
      build_cross_radius_list<D>(sp(a), std::span<const Real>(ra), sp(b), std::span<const Real>(rb),
                                 nl, scratch);
      SCOPED_TRACE(::testing::Message() << "D=" << D << " na=" << na << " spread=" << spread);
      EXPECT_EQ(nl.size(), static_cast<Index>(na));
      EXPECT_EQ(rows_of(nl), expected);
    }
  }
}

// CrossIndex: b bucketed once, queried with several sets (inside b's box, straddling it, far
// outside it, empty): each query is brute force's list and build_cross_list's, bit for bit.
template <int D>
void cross_index_matches() {
  const auto b = random_points<D>(900, 0.0, 1.0, 21);
  constexpr Real kR = 0.04;
  CrossIndex<D> index;
  EXPECT_FALSE(index.built());
  index.build(sp(b), kR);
  ASSERT_TRUE(index.built());
  for (const auto& [lo, hi, seed] : {std::tuple{0.0, 1.0, 1}, std::tuple{-0.5, 1.5, 2},
                                     std::tuple{5.0, 6.0, 3}, std::tuple{0.9, 1.02, 4}}) {
    const auto a = random_points<D>(300, lo, hi, static_cast<std::uint64_t>(seed));
    NeighborList from_index, fresh;
    index.query(sp(a), from_index);
    build_cross_list<D>(sp(a), sp(b), kR, fresh);
    const Rows rows = rows_of(from_index);
    EXPECT_EQ(rows, brute_cross<D>(a, b, kR)) << "query set " << seed;
    EXPECT_EQ(rows, rows_of(fresh)) << "query set " << seed;
  }
  NeighborList none;
  index.query(std::span<const Vec<D>>(), none);
  EXPECT_EQ(none.size(), 0);
  std::vector<Vec<D>> bad(3, Vec<D>::Zero());
  bad[1][0] = std::numeric_limits<Real>::quiet_NaN();
  EXPECT_THROW(index.query(sp(bad), none), std::invalid_argument);
  index.clear();
  EXPECT_THROW(index.query(sp(b), none), std::logic_error);
  index.build(std::span<const Vec<D>>(), kR);  // an empty set: every row empty
  index.query(sp(b), none);
  EXPECT_EQ(none.size(), static_cast<Index>(b.size()));
  EXPECT_EQ(none.total_pairs(), 0);
}

TEST(CrossIndex, MatchesBruteForceAndFreshLists2D) {
  cross_index_matches<2>();
}
TEST(CrossIndex, MatchesBruteForceAndFreshLists3D) {
  cross_index_matches<3>();
}

TEST(CrossRadiusList, MatchesBruteForce2D) {
  check_cross_radius_against_brute_force<2>();
}
TEST(CrossRadiusList, MatchesBruteForce3D) {
  check_cross_radius_against_brute_force<3>();
}

TEST(CrossRadiusList, RejectsBadRadiiAndTakesEmptySets) {
  const auto a = random_points<2>(10, 0, 1, 3), b = random_points<2>(6, 0, 1, 4);
  std::vector<Real> ra(a.size(), 0.1), rb(b.size(), 0.2);
  NeighborList nl;
  std::vector<NeighborList> scratch;
  rb[2] = -1;
  EXPECT_THROW(build_cross_radius_list<2>(sp(a), std::span<const Real>(ra), sp(b),
                                          std::span<const Real>(rb), nl, scratch),
               std::invalid_argument);
  rb[2] = 0.2;
  EXPECT_THROW(build_cross_radius_list<2>(sp(a), std::span<const Real>(ra).first(3), sp(b),
                                          std::span<const Real>(rb), nl, scratch),
               std::invalid_argument);
  const std::vector<Vec<2>> none;
  build_cross_radius_list<2>(sp(a), std::span<const Real>(ra), sp(none), std::span<const Real>(),
                             nl, scratch);
  EXPECT_EQ(nl.size(), 10);
  EXPECT_EQ(nl.total_pairs(), 0);
}

TEST(PairRadiusList, OneRadiusIsTheFullList) {
  const auto x = random_points<3>(2000, 0, 1, 5);
  const std::vector<Real> reach(x.size(), 0.07);
  EXPECT_EQ(pair_radius_rows<3>(x, reach), cell_self<3>(x, 0.07, Pairs::Full));
  // A radius exactly at a lattice spacing: the boundary pairs are in, as in the fixed list.
  std::vector<Vec<2>> lattice;
  for (int a = 0; a < 20; ++a)
    for (int b = 0; b < 20; ++b)
      lattice.emplace_back(0.25 * a, 0.25 * b);
  std::vector<Real> r(lattice.size(), 0.25);
  r[7] = 1.0;  // one large radius: its level's pairs reach 4 spacings
  EXPECT_EQ(pair_radius_rows<2>(lattice, r), brute_pair_radius<2>(lattice, r));
}

TEST(PairRadiusList, RejectsBadRadiiAndTakesEmptySets) {
  const auto x = random_points<2>(10, 0, 1, 3);
  std::vector<Real> reach(x.size(), 0.1);
  reach[4] = 0;
  NeighborList nl;
  std::vector<NeighborList> scratch;
  EXPECT_THROW(build_pair_radius_list<2>(sp(x), std::span<const Real>(reach), nl, scratch),
               std::invalid_argument);
  reach[4] = std::numeric_limits<Real>::infinity();
  EXPECT_THROW(build_pair_radius_list<2>(sp(x), std::span<const Real>(reach), nl, scratch),
               std::invalid_argument);
  reach[4] = std::numeric_limits<Real>::quiet_NaN();
  EXPECT_THROW(build_pair_radius_list<2>(sp(x), std::span<const Real>(reach), nl, scratch),
               std::invalid_argument);
  const std::vector<Vec<2>> none;
  build_pair_radius_list<2>(sp(none), std::span<const Real>(), nl, scratch);
  EXPECT_EQ(nl.size(), 0);
}

TEST(PairRadiusList, SameResultForOneAndTwoThreads) {
  const auto x = random_points<3>(40000, 0, 1, 44);
  std::vector<Real> reach(x.size());
  for (std::size_t i = 0; i < x.size(); ++i)
    reach[i] = 0.03 * (1 + 3 * (x[i].norm() < 0.3));  // a hot core
  NeighborList a, b;
  std::vector<NeighborList> s1, s2;
  with_threads(1, [&] { build_pair_radius_list<3>(sp(x), std::span<const Real>(reach), a, s1); });
  with_threads(2, [&] { build_pair_radius_list<3>(sp(x), std::span<const Real>(reach), b, s2); });
  EXPECT_EQ(a.offsets, b.offsets);
  EXPECT_EQ(a.indices, b.indices);
  EXPECT_GT(a.total_pairs(), 0);
}

TEST(CellSortOrder, PermutationGroupedByCell2D) {
  check_sort_order<2>(5000, 0.05, -1, 1, 61);
}
TEST(CellSortOrder, PermutationGroupedByCell3D) {
  check_sort_order<3>(5000, 0.2, 0, 2, 62);
}
TEST(CellSortOrder, ParallelPath) {
  check_sort_order<2>(50000, 0.01, 0, 1, 63);
}

TEST(CellSortOrder, EdgeCases) {
  const std::vector<Vec<2>> none;
  EXPECT_TRUE(cell_sort_order<2>(sp(none), 1.0).empty());
  const std::vector<Vec<2>> same(5, Vec<2>(2, 2));
  EXPECT_EQ(cell_sort_order<2>(sp(same), 1.0), (std::vector<Index>{0, 1, 2, 3, 4}));
  // Reversed along x, one per cell (spacing 1, cells 0.9): the order reverses.
  std::vector<Vec<2>> row;
  for (int i = 0; i < 6; ++i) {
    row.push_back(Vec<2>(5.0 - i, 0.0));
  }
  EXPECT_EQ(cell_sort_order<2>(sp(row), 0.9), (std::vector<Index>{5, 4, 3, 2, 1, 0}));
  EXPECT_THROW(cell_sort_order<2>(sp(row), 0.0), std::invalid_argument);
}

TEST(CellGrid, EmptySinglePointAndCoincident) {
  const std::vector<Vec<3>> none;
  const GridSpec<3> g0 = make_grid_spec<3>(sp(none), 0.5);
  EXPECT_EQ(g0.cell_count(), 1);
  EXPECT_GE(g0.cell_size, 0.5);

  const std::vector<Vec<3>> one{Vec<3>(1, 2, 3)};
  const GridSpec<3> g1 = make_grid_spec<3>(sp(one), 0.5);
  EXPECT_EQ(g1.cell_count(), 1);
  EXPECT_EQ(g1.cell_index(one[0]), 0);

  const std::vector<Vec<3>> same(1000, Vec<3>(-4, 0, 4));
  const GridSpec<3> g2 = make_grid_spec<3>(sp(same), 1e-300);
  EXPECT_EQ(g2.cell_count(), 1);
  EXPECT_TRUE(std::isfinite(g2.cell_size));
}

TEST(CellGrid, MaxFaceInsideAndCellSizeAtLeastRequested) {
  std::vector<Vec<2>> x{Vec<2>(0, 0), Vec<2>(3, 1), Vec<2>(1.5, 0.5)};
  const GridSpec<2> g = make_grid_spec<2>(sp(x), 0.5);
  EXPECT_GE(g.cell_size, 0.5);
  EXPECT_LT(g.cell_size, 0.5 * 1.001);
  EXPECT_EQ(g.dims, (IVec<2>(6, 2)));  // 3/0.5 = 6 rounds down just below 6 with the margin
  EXPECT_EQ(g.cell_coords(x[0]), (IVec<2>(0, 0)));
  EXPECT_EQ(g.cell_coords(x[1]), (IVec<2>(5, 1)));
  // Points outside the box clamp into boundary cells.
  EXPECT_EQ(g.cell_coords(Vec<2>(-1e300, 1e300)), (IVec<2>(0, 1)));
}

// The grid's cells are those of the lattice anchored at 0: its first cell holds the lowest
// point, and shifting the points a little (without crossing a face) leaves every cell index
// unchanged, so a re-sorted part stays sorted.
TEST(CellGrid, CellsAreOnTheLatticeAnchoredAtZero) {
  auto x = random_points<2>(500, 0.3, 9.7, 17);
  x.push_back(Vec<2>(0.3, 0.3));
  x.push_back(Vec<2>(9.7, 9.7));
  const GridSpec<2> g = make_grid_spec<2>(sp(x), 0.5);
  for (int k = 0; k < 2; ++k) {
    const Real first_face = static_cast<Real>(g.base[k]) * g.cell_size;
    EXPECT_LE(first_face, 0.3);
    EXPECT_GT(first_face, 0.3 - g.cell_size);
  }
  std::vector<Vec<2>> shifted = x;
  for (auto& p : shifted)
    p += Vec<2>(0.01, -0.01);
  const GridSpec<2> gs = make_grid_spec<2>(sp(shifted), 0.5);
  EXPECT_EQ(gs.base, g.base);
  Index moved = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    moved += g.cell_index(x[i]) != gs.cell_index(shifted[i]);
  }
  // Only points within 0.01 of a face change cell: a few percent, not all of them.
  EXPECT_LT(moved, 50);
  // Huge coordinates with a tiny cell: no snapping, no overflow.
  const std::vector<Vec<2>> far(3, Vec<2>(-4.0, 4.0));
  const GridSpec<2> gf = make_grid_spec<2>(sp(far), 1e-300);
  EXPECT_EQ(gf.cell_count(), 1);
}

TEST(CellGrid, CellCountIsCapped) {
  std::vector<Vec<3>> x{Vec<3>(0, 0, 0), Vec<3>(1e6, 1e6, 1e6), Vec<3>(-5e5, 0, 1)};
  const GridSpec<3> g = make_grid_spec<3>(sp(x), 1e-3);
  EXPECT_LE(g.cell_count(), 4 * 3 + 64);
  EXPECT_GE(g.cell_size, 1e-3);
  for (const auto& p : x) {
    const IVec<3> c = g.cell_coords(p);
    EXPECT_TRUE((c.array() >= 0).all() && (c.array() < g.dims.array()).all());
  }
  // A huge extent/size ratio must neither overflow nor allocate absurdly.
  const GridSpec<3> h = make_grid_spec<3>(sp(x), 1e-300);
  EXPECT_LE(h.cell_count(), 4 * 3 + 64);
}

}  // namespace
}  // namespace crater::neighbors
