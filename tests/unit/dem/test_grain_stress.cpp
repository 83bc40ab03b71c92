// Unit tests of the grains' Love-Weber stress (src/dem/laws/grain_stress.hpp): two grains
// pressed together by a known force, a grain on a floor, the components' order and symmetry.
// Reference values are by hand (numbers in the comments); tolerances are rounding level.
#include <gtest/gtest.h>

#include <numbers>

#include "dem/laws/contact_geometry.hpp"
#include "dem/laws/grain_stress.hpp"

namespace crater::dem {
namespace {

constexpr Real kPi = std::numbers::pi;
constexpr Real kRoundoff = 1e-12;  // relative

// Two disks (2D, per metre) of radii 4 and 6 mm, overlapping by 0.1 mm along x, pressed
// together by F = 300 N/m: each grain's contact arm points at the other, the force back, so
// sigma_xx = -a_k F / V_k (compression negative) and nothing else, with a_k = r_k - delta/2
// and V_k = pi r_k^2 / phi.
TEST(GrainStress, TwoDisksPressedTogether) {
  const Real r1 = 4e-3, r2 = 6e-3, delta = 1e-4, force = 300, phi = 0.8;
  const Vec<2> x1(0, 0), x2(r1 + r2 - delta, 0);
  // Body 1 is the grain of lower id; n points from 2 to 1 (-x), the force on 1 along n.
  const ContactGeometry<2> g = sphere_sphere_geometry<2>(x1, r1, x2, r2);
  const Vec<2> f1 = force * g.normal;
  const SymTensor s1 =
      grain_stress(contact_moment<2>(Vec<2>(-g.arm1 * g.normal), f1), kPi * r1 * r1, phi);
  const SymTensor s2 =
      grain_stress(contact_moment<2>(Vec<2>(g.arm2 * g.normal), Vec<2>(-f1)), kPi * r2 * r2, phi);
  const Real a1 = r1 - delta / 2, a2 = r2 - delta / 2;
  EXPECT_NEAR(s1[0], -a1 * force * phi / (kPi * r1 * r1), kRoundoff * 2e4);  // -1.89e4 Pa
  EXPECT_NEAR(s2[0], -a2 * force * phi / (kPi * r2 * r2), kRoundoff * 2e4);  // -1.26e4 Pa
  for (const int k : {1, 2, 3, 4, 5}) {
    EXPECT_EQ(s1[k], 0) << k;
    EXPECT_EQ(s2[k], 0) << k;
  }
}

// The pair's two moments add up to the branch vector times the force, (x_2 - x_1) (x) f_1,
// whatever the contact point (a_1 + a_2 = |x_1 - x_2|): the pair's share of a
// region's mean stress. A tangential force makes each moment's xy term the mean of a_x f_y
// and a_y f_x.
TEST(GrainStress, PairMomentsSumToBranchVectorTimesForce) {
  const Vec<3> x1(0.01, 0.02, -0.005), x2(0.017, 0.025, 0.001);
  const Real r1 = 5e-3, r2 = 6e-3;
  const ContactGeometry<3> g = sphere_sphere_geometry<3>(x1, r1, x2, r2);
  ASSERT_TRUE(g.touching());
  const Vec<3> f1(120, -40, 75);  // normal and tangential parts
  const SymTensor m = contact_moment<3>(Vec<3>(-g.arm1 * g.normal), f1) +
                      contact_moment<3>(Vec<3>(g.arm2 * g.normal), Vec<3>(-f1));
  const Vec<3> b = x2 - x1;
  const Real expect[6] = {b[0] * f1[0],
                          b[1] * f1[1],
                          b[2] * f1[2],
                          0.5 * (b[0] * f1[1] + b[1] * f1[0]),
                          0.5 * (b[1] * f1[2] + b[2] * f1[1]),
                          0.5 * (b[0] * f1[2] + b[2] * f1[0])};
  for (int k = 0; k < 6; ++k)
    EXPECT_NEAR(m[k], expect[k], 1e-12) << k;  // |terms| ~ 1 N m
}

// A disk resting on a floor (the wall point below it, n = +y): the floor pushes up with its
// weight m g, the arm r - delta points down: sigma_yy = -(r - delta) m g phi / V.
TEST(GrainStress, DiskOnFloor) {
  const Real r = 5e-3, delta = 2e-6, rho = 1920, g0 = 9.81, phi = 0.82;
  const Vec<2> x(0.3, -0.3 + r - delta);
  const ContactGeometry<2> g = sphere_wall_geometry<2>(x, r, Vec<2>(0.3, -0.3));
  const Real weight = rho * kPi * r * r * g0;  // 1.48 N/m
  const SymTensor s = grain_stress(contact_moment<2>(Vec<2>(-g.arm1 * g.normal), Vec<2>(0, weight)),
                                   kPi * r * r, phi);
  EXPECT_NEAR(s[1], -(r - delta) * rho * g0 * phi, kRoundoff * 100);  // -77.2 Pa
  EXPECT_EQ(s[0], 0);
  EXPECT_EQ(s[3], 0);
}

// VTK's order: xx, yy, zz, xy, yz, xz.
TEST(GrainStress, ComponentOrderIsVtks) {
  const SymTensor m = contact_moment<3>(Vec<3>(1, 2, 3), Vec<3>(5, 7, 11));
  EXPECT_EQ(m[0], 5);
  EXPECT_EQ(m[1], 14);
  EXPECT_EQ(m[2], 33);
  EXPECT_EQ(m[3], 0.5 * (1 * 7 + 2 * 5));
  EXPECT_EQ(m[4], 0.5 * (2 * 11 + 3 * 7));
  EXPECT_EQ(m[5], 0.5 * (1 * 11 + 3 * 5));
}

}  // namespace
}  // namespace crater::dem
