// Programmed burn's lighting time (sph_setup.hpp, lighting_time) for the three initiators of
// [[parts.detonation]]: a particle lights at time_s + (distance to the initiator) / D, the
// distance to a point, to a plane (either side) or to a line, exactly as geometry gives it.
#include <gtest/gtest.h>

#include <cmath>

#include "sph/sph_setup.hpp"

namespace crater::sph {
namespace {

constexpr Real kD = 6930.0;

parts::PartSetup with(parts::DetonationPoint dp) {
  parts::PartSetup s;
  s.detonations.push_back(dp);
  return s;
}

TEST(Initiators, PointIsTheDistanceToThePoint) {
  const auto s = with({parts::Initiator::Point, {1.0, 2.0, 3.0}, {}, 1e-6});
  const Vec<3> x(4.0, 6.0, 3.0);  // 5 m away
  EXPECT_DOUBLE_EQ(lighting_time<3>(s, true, kD, x), 1e-6 + 5.0 / kD);
}

TEST(Initiators, PlaneLightsBothSidesByTheNormalDistance) {
  // The plane x = 0.5 (normal along x): the lateral position does not matter.
  const auto s = with({parts::Initiator::Plane, {0.5, 7.0, -3.0}, {1.0, 0.0, 0.0}, 0.0});
  for (const Real y : {-10.0, 0.0, 42.0}) {
    EXPECT_DOUBLE_EQ(lighting_time<3>(s, true, kD, Vec<3>(0.8, y, y)), 0.3 / kD);
    EXPECT_DOUBLE_EQ(lighting_time<3>(s, true, kD, Vec<3>(0.2, y, -y)), 0.3 / kD);
  }
  // A tilted plane: x + y = 1 (unit normal (1, 1)/sqrt 2) in 2D.
  const Real r = 1 / std::sqrt(Real(2));
  const auto t = with({parts::Initiator::Plane, {1.0, 0.0, 0.0}, {r, r, 0.0}, 0.0});
  EXPECT_NEAR(lighting_time<2>(t, true, kD, Vec<2>(1.0, 1.0)), r / kD, 1e-15 / kD);
}

TEST(Initiators, LineIsTheDistanceToTheLine) {
  // The z axis through (1, 1): a particle 3-4-5 from it, anywhere along it.
  const auto s = with({parts::Initiator::Line, {1.0, 1.0, 0.0}, {0.0, 0.0, 1.0}, 2e-6});
  for (const Real z : {-5.0, 0.0, 9.0})
    EXPECT_DOUBLE_EQ(lighting_time<3>(s, true, kD, Vec<3>(4.0, 5.0, z)), 2e-6 + 5.0 / kD);
}

TEST(Initiators, TheEarliestInitiatorWins) {
  parts::PartSetup s;
  s.detonations.push_back({parts::Initiator::Point, {0.0, 0.0, 0.0}, {}, 0.0});
  s.detonations.push_back({parts::Initiator::Plane, {10.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, 0.0});
  EXPECT_DOUBLE_EQ(lighting_time<2>(s, true, kD, Vec<2>(9.0, 0.0)), 1.0 / kD);
  EXPECT_DOUBLE_EQ(lighting_time<2>(s, true, kD, Vec<2>(2.0, 0.0)), 2.0 / kD);
}

}  // namespace
}  // namespace crater::sph
