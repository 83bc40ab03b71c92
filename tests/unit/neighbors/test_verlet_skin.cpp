// VerletSkin: a list built for (1 + skin) x need stays valid until some point has moved half the
// margin, skin x need / 2 (Verlet 1967); stale_given, fed the largest squared displacement the
// owner measured itself, says what stale says.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <span>
#include <vector>

#include "neighbors/verlet_skin.hpp"

namespace crater::neighbors {
namespace {

Real largest_squared_move(const std::vector<Vec<3>>& x, std::span<const Vec<3>> built) {
  Real m = 0;
  for (std::size_t i = 0; i < x.size(); ++i)
    m = std::max(m, (x[i] - built[i]).squaredNorm());
  return m;
}

TEST(VerletSkin, StaleWithoutAList) {
  const VerletSkin<3> skin(0.3);
  const std::vector<Vec<3>> x(4, Vec<3>::Zero());
  EXPECT_TRUE(skin.stale(x, 1.0));
  EXPECT_TRUE(skin.stale_given(0.0, 4, 1.0));
}

TEST(VerletSkin, HalfTheMarginIsTheLimit) {
  const Real need = 2e-3, skin_fraction = 0.3, half_margin = 0.5 * skin_fraction * need;
  VerletSkin<3> skin(skin_fraction);
  std::vector<Vec<3>> x(10, Vec<3>::Zero());
  for (std::size_t i = 0; i < x.size(); ++i)
    x[i] = Vec<3>(1e-3 * static_cast<Real>(i), 0, 0);
  EXPECT_DOUBLE_EQ(skin.built(x, need), (1 + skin_fraction) * need);
  for (const Real f : {0.0, 0.5, 0.999}) {
    std::vector<Vec<3>> moved = x;
    moved[3].y() += f * half_margin;
    EXPECT_FALSE(skin.stale(moved, need)) << f;
    EXPECT_FALSE(skin.stale_given(largest_squared_move(moved, skin.positions()), 10, need)) << f;
  }
  std::vector<Vec<3>> moved = x;
  moved[7].z() -= 1.001 * half_margin;
  EXPECT_TRUE(skin.stale(moved, need));
  EXPECT_TRUE(skin.stale_given(largest_squared_move(moved, skin.positions()), 10, need));
  // A larger interaction radius than the list was built for needs a new list at once.
  EXPECT_TRUE(skin.stale(x, 1.2 * (1 + skin_fraction) * need));
  // Another number of points: the list's indices are void.
  EXPECT_TRUE(skin.stale_given(0.0, 9, need));
}

TEST(VerletSkin, GivenAgreesWithMeasuredOnRandomMoves) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<Real> u(-1, 1);
  const Real need = 1.0;
  VerletSkin<3> skin(0.3);
  std::vector<Vec<3>> x(200);
  for (auto& p : x)
    p = Vec<3>(u(rng), u(rng), u(rng));
  skin.built(x, need);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<Vec<3>> moved = x;
    const Real scale = 0.2 * static_cast<Real>(trial) / 200;  // up to beyond the 0.15 limit
    for (auto& p : moved)
      p += scale * Vec<3>(u(rng), u(rng), u(rng));
    EXPECT_EQ(skin.stale_given(largest_squared_move(moved, skin.positions()), 200, need),
              skin.stale(moved, need))
        << trial;
  }
}

}  // namespace
}  // namespace crater::neighbors
