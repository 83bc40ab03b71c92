// Unit tests of the 3D probes' geometry (src/solver/probe_geometry.cpp): rings of a surface
// profile, the crater read off them, and a plate's perforated footprint, against answers
// worked by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "solver/probe_geometry.hpp"

namespace crater::solver {
namespace {

TEST(RingProfile, MeansTheColumnsOfEachRingWithSurfacesAtBothTimes) {
  // Width 1: ring 0 holds r = 0.2 and 0.6, ring 1 is empty (its one column has no surface
  // now), ring 2 holds r = 2.5; ring 3's column has none at t = 0.
  const Real nan = std::nan("");
  const std::vector<Real> r = {0.2, 0.6, 1.5, 2.5, 3.5};
  const std::vector<Real> s0 = {0.0, 0.0, 0.0, 0.1, nan};
  const std::vector<Real> s = {-0.4, -0.2, nan, 0.05, 0.0};
  const auto rings = ring_profile(r, s0, s, 1.0);
  ASSERT_EQ(rings.size(), 2u);
  EXPECT_DOUBLE_EQ(rings[0].r_m, 0.4);
  EXPECT_DOUBLE_EQ(rings[0].surface_m, -0.3);
  EXPECT_DOUBLE_EQ(rings[0].drop_m(), 0.3);
  EXPECT_DOUBLE_EQ(rings[1].r_m, 2.5);
  EXPECT_NEAR(rings[1].drop_m(), 0.05, 1e-15);
}

TEST(CraterOfProfile, RadiusWhereTheDropCrossesTheThresholdBetweenRings) {
  // Drops 0.5, 0.4, 0.1 at r = 0, 1, 2, threshold 0.2: 0.4 -> 0.1 crosses 0.2 two thirds of
  // the way from r = 1 to r = 2.
  std::vector<Ring> rings = {{0, 0, -0.5}, {1, 0, -0.4}, {2, 0, -0.1}, {3, 0, -0.3}};
  const CraterSize c = crater_of_profile(rings, 0.2);
  EXPECT_DOUBLE_EQ(c.depth_m, 0.5);
  EXPECT_NEAR(c.radius_m, 1 + 2.0 / 3.0, 1e-12);
  EXPECT_FALSE(c.reaches_end);
}

TEST(CraterOfProfile, StartsAtTheDeepestRingAndStopsAtTheProfilesEnd) {
  // A mound on the axis (drop -0.1), the deepest ring at r = 2: the crater goes out from it
  // and never falls below the threshold, so its radius is the last ring's.
  std::vector<Ring> rings = {{0, 0, 0.1}, {1, 0, -0.3}, {2, 0, -0.6}, {3, 0, -0.25}};
  const CraterSize c = crater_of_profile(rings, 0.2);
  EXPECT_DOUBLE_EQ(c.depth_m, 0.6);
  EXPECT_DOUBLE_EQ(c.radius_m, 3.0);
  EXPECT_TRUE(c.reaches_end);
  // No ring dropped by more than the threshold: no crater.
  const CraterSize none = crater_of_profile({{0, 0, -0.1}, {1, 0, 0.0}}, 0.2);
  EXPECT_EQ(none.depth_m, 0.0);
  EXPECT_EQ(none.radius_m, 0.0);
  EXPECT_FALSE(none.reaches_end);
}

/// A box-meshed plate of nx x ny x nz hexahedra of size h (nodes numbered x fastest, then y,
/// then z; each element's nodes bottom face then top face, as VTK's hexahedron).
struct HexPlate {
  std::vector<Vec<3>> x;
  std::vector<std::int64_t> connectivity, offsets;
  int nx, ny, nz;
  HexPlate(int nx_, int ny_, int nz_, Real h) : nx(nx_), ny(ny_), nz(nz_) {
    for (int k = 0; k <= nz; ++k)
      for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i)
          x.push_back(Vec<3>(i * h, j * h, k * h));
    auto node = [&](int i, int j, int k) {
      return static_cast<std::int64_t>(i + (nx + 1) * (j + (ny + 1) * k));
    };
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          for (int dk = 0; dk < 2; ++dk) {
            connectivity.push_back(node(i, j, k + dk));
            connectivity.push_back(node(i + 1, j, k + dk));
            connectivity.push_back(node(i + 1, j + 1, k + dk));
            connectivity.push_back(node(i, j + 1, k + dk));
          }
          offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
        }
  }
  std::size_t element(int i, int j, int k) const {
    return static_cast<std::size_t>(i + nx * (j + ny * k));
  }
};

TEST(PerforatedFootprint, SumsTheColumnsErodedThroughTheThickness) {
  // 4 x 3 columns of 0.5 m x 0.5 m, two elements thick. Columns (0,0) and (2,1) are eroded
  // through; column (3,2) only in its bottom layer: 2 x 0.25 m^2 are open.
  const HexPlate p(4, 3, 2, 0.5);
  std::vector<std::uint8_t> eroded(p.offsets.size(), 0);
  for (int k = 0; k < 2; ++k) {
    eroded[p.element(0, 0, k)] = 1;
    eroded[p.element(2, 1, k)] = 1;
  }
  eroded[p.element(3, 2, 0)] = 1;
  EXPECT_NEAR(perforated_footprint<3>({p.x, p.connectivity, p.offsets, eroded}), 0.5, 1e-12);
}

TEST(PerforatedFootprint, NodesOnAVerticalLineMatchUpToRoundOff) {
  // Reference positions recovered as position - displacement differ in the last bits from
  // one layer to the next; the columns must still be found.
  HexPlate p(2, 2, 3, 0.1);
  for (std::size_t n = 0; n < p.x.size(); ++n)
    p.x[n][0] += 1e-15 * static_cast<Real>(n % 3);
  std::vector<std::uint8_t> eroded(p.offsets.size(), 1);
  EXPECT_NEAR(perforated_footprint<3>({p.x, p.connectivity, p.offsets, eroded}), 0.04, 1e-12);
  eroded[p.element(1, 1, 2)] = 0;  // one live element keeps its column covered
  EXPECT_NEAR(perforated_footprint<3>({p.x, p.connectivity, p.offsets, eroded}), 0.03, 1e-12);
}

TEST(PerforatedFootprint, TwoDimensionalPlateIsALength) {
  // 5 quads of 0.2 m along x, 2 through the thickness; the middle column eroded through, the
  // last one only at the bottom: 0.2 m open.
  std::vector<Vec<2>> x;
  for (int k = 0; k <= 2; ++k)
    for (int i = 0; i <= 5; ++i)
      x.push_back(Vec<2>(0.2 * i, 0.1 * k));
  std::vector<std::int64_t> conn, off;
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < 5; ++i) {
      for (const int n : {i + 6 * k, i + 1 + 6 * k, i + 1 + 6 * (k + 1), i + 6 * (k + 1)})
        conn.push_back(n);
      off.push_back(static_cast<std::int64_t>(conn.size()));
    }
  std::vector<std::uint8_t> eroded(off.size(), 0);
  eroded[2] = eroded[7] = 1;
  eroded[4] = 1;
  EXPECT_NEAR(perforated_footprint<2>({x, conn, off, eroded}), 0.2, 1e-12);
}

}  // namespace
}  // namespace crater::solver
