// The cells of a contact zone (src/contact/contact_zone.hpp) against a brute-force search over
// every pair: every particle within the reach of a marked point must be near (the zone holds
// every pair in contact), and a particle further than the cell stencil reaches (two cells'
// diagonal) must not be, in 2D and 3D, with the marks compact (a bitmap) and spread (sorted
// keys), at negative coordinates too.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "contact/contact_zone.hpp"
#include "contact/face_search.hpp"

namespace crater::contact {
namespace {

template <int D>
std::vector<Vec<D>> points(std::mt19937_64& rng, int n, Real lo, Real hi) {
  std::uniform_real_distribution<Real> u(lo, hi);
  std::vector<Vec<D>> x(static_cast<std::size_t>(n));
  for (auto& p : x)
    for (int d = 0; d < D; ++d)
      p[d] = u(rng);
  return x;
}

template <int D>
void check_against_brute_force(Real spread) {
  std::mt19937_64 rng(7 + D);
  const Real reach = 0.03;
  // The other side: a few points clustered (compact) or strewn over a wide box (spread).
  const auto marks = points<D>(rng, 40, -spread, spread);
  const auto bodies = points<D>(rng, 4000, -spread - 0.1, spread + 0.1);
  ZoneCells<D> cells(reach);
  for (const auto& m : marks)
    cells.occupy(m);
  cells.seal(nullptr);
  const Real stencil = 2 * reach * std::sqrt(Real(D)) * (1 + 1e-6);
  int within = 0, far = 0;
  for (const auto& x : bodies) {
    Real nearest = std::numeric_limits<Real>::infinity();
    for (const auto& m : marks)
      nearest = std::min(nearest, (x - m).norm());
    if (nearest <= reach) {
      ++within;
      EXPECT_TRUE(cells.near(x)) << "a body within reach of a mark is outside the zone";
    }
    if (nearest > stencil) {
      ++far;
      EXPECT_FALSE(cells.near(x)) << "a body beyond the stencil is in the zone";
    }
  }
  EXPECT_GT(far, 0);
  // Bodies placed within reach of each mark, so that the first check runs on many.
  std::uniform_real_distribution<Real> u(-1, 1);
  for (const auto& m : marks)
    for (int k = 0; k < 20; ++k) {
      Vec<D> dir;
      for (int d = 0; d < D; ++d)
        dir[d] = u(rng);
      if (dir.norm() == 0) continue;
      const Vec<D> x = m + (reach * u(rng)) * dir.normalized();
      ++within;
      EXPECT_TRUE(cells.near(x));
    }
  EXPECT_GT(within, 40);
}

TEST(ZoneCells, HoldsEveryBodyWithinReach2DCompact) {
  check_against_brute_force<2>(0.2);
}
TEST(ZoneCells, HoldsEveryBodyWithinReach2DSpread) {
  check_against_brute_force<2>(500.0);
}
TEST(ZoneCells, HoldsEveryBodyWithinReach3DCompact) {
  check_against_brute_force<3>(0.2);
}
TEST(ZoneCells, HoldsEveryBodyWithinReach3DSpread) {
  check_against_brute_force<3>(500.0);
}

// What a zone kept across a surface's erosion relies on (spread_zone.cpp, faces_marked): a point
// in a marked cell, though not itself marked, has every body within the reach near, as a mark
// has. Checked against brute force; and the marks' own cells are marked, a far point's not.
template <int D>
void check_marked_cells(Real spread) {
  std::mt19937_64 rng(11 + D);
  const Real reach = 0.03;
  const auto marks = points<D>(rng, 40, -spread, spread);
  ZoneCells<D> cells(reach);
  for (const auto& m : marks)
    cells.occupy(m);
  cells.seal(nullptr);
  for (const auto& m : marks)
    EXPECT_TRUE(cells.marks(m));
  EXPECT_FALSE(cells.marks(Vec<D>::Constant(10 * spread + 1)));
  EXPECT_FALSE(cells.marks(Vec<D>::Constant(std::numeric_limits<Real>::quiet_NaN())));
  // Probes about the marks (within a cell of one, so that some share its cell), and bodies
  // within the reach of each probe in a marked cell.
  std::uniform_real_distribution<Real> u(-1, 1);
  int in_marked = 0, beside = 0;
  for (const auto& m : marks)
    for (int k = 0; k < 30; ++k) {
      Vec<D> y = m;
      for (int d = 0; d < D; ++d)
        y[d] += reach * u(rng);
      if (!cells.marks(y)) {
        ++beside;
        continue;
      }
      ++in_marked;
      for (int b = 0; b < 10; ++b) {
        Vec<D> dir;
        for (int d = 0; d < D; ++d)
          dir[d] = u(rng);
        if (dir.norm() == 0) continue;
        const Vec<D> x = y + (reach * std::abs(u(rng))) * dir.normalized();
        EXPECT_TRUE(cells.near(x)) << "a body within reach of a point in a marked cell is out";
      }
    }
  EXPECT_GT(in_marked, 100);
  EXPECT_GT(beside, 10);
}

TEST(ZoneCells, APointInAMarkedCellHasItsReachInTheZone2D) {
  check_marked_cells<2>(0.2);
  check_marked_cells<2>(500.0);
}
TEST(ZoneCells, APointInAMarkedCellHasItsReachInTheZone3D) {
  check_marked_cells<3>(0.2);
  check_marked_cells<3>(500.0);
}

// A zone found for a surface kept across an erosion (faces_in_marked_cells): a plate of two
// layers of elements, its top faces marked; a new list with the same faces, or with the faces of
// the layer below exposed under a removed top face (one element deep, in the same cells) keeps
// it; a face of the bottom layer two cells down does not. The decision reads the positions
// given (those of the zone's finding), not the surface's own.
template <int D>
void check_faces_in_marked_cells() {
  const Real reach = 0.03, h = 0.02;  // cells 3 cm across, elements 2 cm
  const int n = 12;
  // Nodes on three levels: the top in the cells' row -1 (y in [-3, 0) cm), one element down
  // in the same row, and four elements down, two rows further.
  const Real top_y = -0.001;
  const std::array<Real, 3> levels{top_y, top_y - h, top_y - 4 * h};
  std::vector<Vec<D>> x;
  const int depth = D == 3 ? n + 1 : 1;
  auto node = [&](int level, int i, int k) {
    return static_cast<Index>((level * depth + k) * (n + 1) + i);
  };
  for (int level = 0; level < 3; ++level)
    for (int k = 0; k < depth; ++k)
      for (int i = 0; i <= n; ++i) {
        Vec<D> p = Vec<D>::Zero();
        p[0] = h * i;
        p[1] = levels[at(level)];
        if constexpr (D == 3) p[2] = h * k;
        x.push_back(p);
      }
  using Face = std::array<Index, parts::kFaceNodes<D>>;
  auto faces_on = [&](int level) {
    std::vector<Face> f;
    for (int k = 0; k < (D == 3 ? n : 1); ++k)
      for (int i = 0; i < n; ++i) {
        if constexpr (D == 2)
          f.push_back({node(level, i, 0), node(level, i + 1, 0)});
        else
          f.push_back({node(level, i, k), node(level, i + 1, k), node(level, i + 1, k + 1),
                       node(level, i, k + 1)});
      }
    return f;
  };
  const std::vector<Face> top = faces_on(0);
  parts::ContactSurface<D> surface;
  surface.node_position = &x;
  surface.faces = &top;
  ZoneCells<D> cells(reach);
  for (const Vec<D>& c : face_centres(surface).centre)
    cells.occupy(c);
  cells.seal(nullptr);
  EXPECT_TRUE(faces_in_marked_cells(surface, x, cells));
  // The surface has moved far since: the decision takes the positions it is given.
  std::vector<Vec<D>> moved = x;
  for (auto& p : moved)
    p[0] += 10;
  parts::ContactSurface<D> now = surface;
  now.node_position = &moved;
  EXPECT_TRUE(faces_in_marked_cells(now, x, cells));
  EXPECT_FALSE(faces_in_marked_cells(surface, moved, cells));
  // A top face gone and the face one element below it exposed: still in the marked cells.
  std::vector<Face> eroded = top;
  eroded.erase(eroded.begin() + 3);
  eroded.push_back(faces_on(1)[3]);
  now.faces = &eroded;
  EXPECT_TRUE(faces_in_marked_cells(now, x, cells));
  // A face two cells down: the zone must be found again.
  eroded.push_back(faces_on(2)[5]);
  EXPECT_FALSE(faces_in_marked_cells(now, x, cells));
}

TEST(ZoneCells, ASurfaceListedAgainKeepsItsZoneWhileItsFacesAreInMarkedCells2D) {
  check_faces_in_marked_cells<2>();
}
TEST(ZoneCells, ASurfaceListedAgainKeepsItsZoneWhileItsFacesAreInMarkedCells3D) {
  check_faces_in_marked_cells<3>();
}

TEST(ZoneCells, NothingMarkedOrNoReach) {
  ZoneCells<2> empty(0.1);
  empty.seal(nullptr);
  EXPECT_FALSE(empty.near(Vec<2>(0, 0)));
  ZoneCells<2> none(0.0);  // no reach: nothing is marked
  none.occupy(Vec<2>(0, 0));
  none.seal(nullptr);
  EXPECT_FALSE(none.near(Vec<2>(0, 0)));
  // A non-finite body is always in (the pairing then meets it as on one rank); a non-finite
  // mark marks nothing.
  ZoneCells<2> one(0.1);
  one.occupy(Vec<2>(std::numeric_limits<Real>::quiet_NaN(), 0));
  one.seal(nullptr);
  EXPECT_FALSE(one.near(Vec<2>(0, 0)));
  EXPECT_TRUE(one.near(Vec<2>(std::numeric_limits<Real>::infinity(), 0)));
}

}  // namespace
}  // namespace crater::contact
