// The cells of a contact zone (src/contact/contact_zone.hpp) against a brute-force search over
// every pair: every particle within the reach of a marked point must be near (the zone holds
// every pair in contact), and a particle further than the cell stencil reaches (two cells'
// diagonal) must not be, in 2D and 3D, with the marks compact (a bitmap) and spread (sorted
// keys), at negative coordinates too.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "contact/contact_zone.hpp"

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
