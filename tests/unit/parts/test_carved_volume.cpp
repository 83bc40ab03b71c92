// parts::carved_volume: the part of a box that carved regions take, against exact areas and
// volumes (a box overlap, a disk or ball inside, half a disk and an eighth of a ball cut by the
// box's faces; the counted cases within their stated 1e-3).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "parts/region.hpp"

namespace crater::parts {
namespace {

RegionConfig box(Vec3 lo, Vec3 hi) {
  RegionConfig r;
  r.type = RegionType::Box;
  r.min_m = lo;
  r.max_m = hi;
  return r;
}

RegionConfig ball(Vec3 c, Real radius) {
  RegionConfig r;
  r.type = RegionType::Disk;
  r.center_m = c;
  r.radius_m = radius;
  return r;
}

TEST(CarvedVolume, ExactForBoxesAndBallsInside) {
  const RegionConfig b = box({0, 0, 0}, {4, 2, 1});
  EXPECT_DOUBLE_EQ(carved_volume<2>(b, {box({3, -1, 0}, {5, 0.5, 0})}), 1.0 * 0.5);
  EXPECT_DOUBLE_EQ(carved_volume<2>(b, {ball({2, 1, 0}, 0.5)}), std::numbers::pi * 0.25);
  EXPECT_DOUBLE_EQ(carved_volume<3>(b, {ball({2, 1, 0.5}, 0.5)}),
                   4.0 / 3.0 * std::numbers::pi * 0.125);
}

TEST(CarvedVolume, CountedWhereAFaceCutsTheBall) {
  const RegionConfig b = box({0, 0, 0}, {4, 2, 1});
  // Half a disk below the top face (y = 2); an eighth of a ball in the corner (0, 0, 0).
  const Real half_disk = 0.5 * std::numbers::pi * 0.3 * 0.3;
  EXPECT_NEAR(carved_volume<2>(b, {ball({1, 2, 0}, 0.3)}), half_disk, 1e-3 * half_disk);
  const Real eighth = 4.0 / 3.0 * std::numbers::pi * 0.2 * 0.2 * 0.2 / 8;
  EXPECT_NEAR(carved_volume<3>(b, {ball({0, 0, 0}, 0.2)}), eighth, 1e-3 * eighth);
}

}  // namespace
}  // namespace crater::parts
