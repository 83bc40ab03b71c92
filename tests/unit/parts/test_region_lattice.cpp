// parts::region_lattice cut at planes of symmetry: a sphere centred on two planes (a quarter
// model's charge) gets the points of the whole sphere's mirror-continued lattice on the model's
// side only, each half a pitch off the planes, whichever way the pitch divides the radius.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <tuple>

#include "parts/region.hpp"

namespace crater::parts {
namespace {

RegionConfig sphere(Vec3 c, Real radius) {
  RegionConfig r;
  r.type = RegionType::Sphere;
  r.center_m = c;
  r.radius_m = radius;
  return r;
}

// The points of a lattice aligned half a pitch off the planes x = 0, y = 0 (and along z, as
// uncut: n = floor(2 r / s) points centred on the sphere), inside the sphere, counted by brute
// force over the model's quadrant.
std::size_t quadrant_count(const RegionConfig& r, Real s) {
  std::size_t n = 0;
  const Real rad = r.radius_m;
  const auto k_max = static_cast<int>(std::ceil(2 * rad / s)) + 2;
  const auto nz = static_cast<int>(std::floor(2 * rad / s + 1e-9));
  for (int i = 0; i < k_max; ++i)
    for (int j = 0; j < k_max; ++j)
      for (int k = 0; k < nz; ++k) {
        const Vec<3> x((i + 0.5) * s, (j + 0.5) * s, r.center_m[2] - 0.5 * (nz - 1) * s + k * s);
        if (region_contains<3>(r, x)) ++n;
      }
  return n;
}

TEST(RegionLattice, CutAtPlanesOfSymmetryHalfAPitchOff) {
  const std::vector<LatticeCut> cuts{{0, 0.0, false}, {1, 0.0, false}};
  // 0.64 / 0.04 = 16 pitches across a radius (even count across the diameter), and 0.62 / 0.04
  // (odd: the centred lattice would put points on the planes).
  for (const Real radius : {0.64, 0.62}) {
    const RegionConfig r = sphere({0, 0, -1.2}, radius);
    const auto pts = region_lattice<3>(r, 0.04, cuts);
    EXPECT_EQ(pts.size(), quadrant_count(r, 0.04)) << "radius " << radius;
    std::set<std::tuple<long, long, long>> seen;
    for (const Vec<3>& x : pts) {
      for (int d = 0; d < 2; ++d) {
        EXPECT_GT(x[d], 0.0);
        const Real k = x[d] / 0.04 - 0.5;  // a whole number of pitches past the first row
        EXPECT_NEAR(k, std::round(k), 1e-9);
      }
      EXPECT_TRUE(region_contains<3>(r, x));
      seen.insert({std::lround(x[0] / 0.02), std::lround(x[1] / 0.02), std::lround(x[2] / 0.02)});
    }
    EXPECT_EQ(seen.size(), pts.size());  // no point twice
  }
}

TEST(RegionLattice, UpperPlaneKeepsTheSideBelow) {
  const std::vector<LatticeCut> cuts{{0, 1.0, true}};
  RegionConfig r = sphere({1.0, 0, 0}, 0.3);
  r.type = RegionType::Disk;
  const auto pts = region_lattice<2>(r, 0.05, cuts);
  ASSERT_FALSE(pts.empty());
  Real x_max = -1;
  for (const Vec<2>& x : pts)
    x_max = std::max(x_max, x[0]);
  EXPECT_NEAR(x_max, 1.0 - 0.025, 1e-12);
}

TEST(RegionLattice, UncutRegionIsUnchanged) {
  const RegionConfig r = sphere({0, 0, 0}, 0.3);
  EXPECT_EQ(region_lattice<3>(r, 0.05).size(),
            region_lattice<3>(r, 0.05, {{0, 5.0, false}}).size());
}

}  // namespace
}  // namespace crater::parts
