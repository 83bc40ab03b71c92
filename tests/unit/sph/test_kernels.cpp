// Unit tests of the SPH smoothing kernels (src/sph/kernels.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <type_traits>

#include "sph/kernels.hpp"

namespace crater::sph {
namespace {

constexpr Real kPi = std::numbers::pi;

/// \int W dV by the midpoint rule on a Cartesian grid of spacing `dx` covering the support.
template <class Kernel>
Real integrate_kernel(Real h, int cells_per_h) {
  constexpr int d = Kernel::dim;
  const Real dx = h / cells_per_h;
  const int n = static_cast<int>(std::lround(2 * Kernel::support * cells_per_h));
  const Real x0 = -Kernel::support * h;
  Real sum = 0;
  if constexpr (d == 2) {
    for (int i = 0; i < n; ++i) {
      const Real x = x0 + (i + 0.5) * dx;
      for (int j = 0; j < n; ++j) {
        const Real y = x0 + (j + 0.5) * dx;
        sum += Kernel::w(std::hypot(x, y), h);
      }
    }
    return sum * dx * dx;
  } else {
    for (int i = 0; i < n; ++i) {
      const Real x = x0 + (i + 0.5) * dx;
      for (int j = 0; j < n; ++j) {
        const Real y = x0 + (j + 0.5) * dx;
        for (int k = 0; k < n; ++k) {
          const Real z = x0 + (k + 0.5) * dx;
          sum += Kernel::w(std::sqrt(x * x + y * y + z * z), h);
        }
      }
    }
    return sum * dx * dx * dx;
  }
}

template <class Kernel>
class KernelTest : public ::testing::Test {};

using KernelTypes = ::testing::Types<WendlandC2<2>, WendlandC2<3>, CubicSpline<2>, CubicSpline<3>>;

class KernelNames {
 public:
  template <class T>
  static std::string GetName(int /*index*/) {
    if constexpr (std::is_same_v<T, WendlandC2<2>>) {
      return "WendlandC2_2D";
    }
    if constexpr (std::is_same_v<T, WendlandC2<3>>) {
      return "WendlandC2_3D";
    }
    if constexpr (std::is_same_v<T, CubicSpline<2>>) {
      return "CubicSpline_2D";
    }
    if constexpr (std::is_same_v<T, CubicSpline<3>>) {
      return "CubicSpline_3D";
    }
    return "unknown";
  }
};
TYPED_TEST_SUITE(KernelTest, KernelTypes, KernelNames);

// \int W dV = 1, midpoint rule with 20 cells per h. Both kernels are C^2 and vanish with their
// first two derivatives at q = 2, so the lattice sum converges much faster than the nominal
// O(dx^2): measured |error| <= 8e-9 (2D and 3D, both kernels) at this spacing, 3e-7 at 10 cells
// per h. The tolerance 1e-4 is thus far above the quadrature error yet far below the error of
// any wrong normalisation constant or missing power of h (>= 1 %).
TYPED_TEST(KernelTest, IntegratesToOne) {
  const Real h = 0.37;  // arbitrary, not 1, so that a missing power of h shows
  EXPECT_NEAR(integrate_kernel<TypeParam>(h, 20), 1.0, 1e-4);
}

TYPED_TEST(KernelTest, NonNegativeAndZeroOutsideSupport) {
  const Real h = 0.01;
  for (int i = 0; i <= 2000; ++i) {
    const Real r = 1.2 * TypeParam::support * h * i / 2000;
    const Real w = TypeParam::w(r, h);
    EXPECT_GE(w, 0.0) << "r/h = " << r / h;
    EXPECT_LE(TypeParam::dw_dr(r, h), 0.0) << "r/h = " << r / h;
    if (r >= TypeParam::support * h) {
      EXPECT_EQ(w, 0.0) << "r/h = " << r / h;
      EXPECT_EQ(TypeParam::dw_dr(r, h), 0.0) << "r/h = " << r / h;
    }
  }
  EXPECT_EQ(TypeParam::support, 2.0);
}

// Central difference with step 1e-6 h: truncation ~ (1e-6)^2 |W'''| h^2, rounding ~ 1e-16 / 1e-6
// relative to W; 1e-7 of the peak |dW/dr| bounds both.
TYPED_TEST(KernelTest, DerivativeMatchesFiniteDifference) {
  const Real h = 0.05;
  const Real step = 1e-6 * h;
  Real peak = 0;
  for (int i = 1; i < 400; ++i) {
    peak = std::max(peak, -TypeParam::dw_dr(2.0 * h * i / 400, h));
  }
  for (int i = 1; i < 400; ++i) {
    const Real r = TypeParam::support * h * (i + 0.37) / 400;
    const Real fd = (TypeParam::w(r + step, h) - TypeParam::w(r - step, h)) / (2 * step);
    EXPECT_NEAR(TypeParam::dw_dr(r, h), fd, 1e-7 * peak) << "r/h = " << r / h;
  }
}

TYPED_TEST(KernelTest, GradientIsAntisymmetricAndPointsInward) {
  constexpr int d = TypeParam::dim;
  const Real h = 0.02;
  Vec<d> rij = Vec<d>::Zero();
  rij(0) = 0.013;
  rij(1) = -0.007;
  if constexpr (d == 3) {
    rij(2) = 0.004;
  }
  const Real r = rij.norm();
  const Vec<d> g_ij = TypeParam::grad_w(rij, r, h);
  const Vec<d> g_ji = TypeParam::grad_w(Vec<d>(-rij), r, h);
  for (int k = 0; k < d; ++k) {
    EXPECT_DOUBLE_EQ(g_ij(k), -g_ji(k));
  }
  // \nabla_i W = (dW/dr) r_ij / r: anti-parallel to r_ij with length |dW/dr|.
  EXPECT_NEAR(g_ij.norm(), -TypeParam::dw_dr(r, h), 1e-12 * g_ij.norm());
  EXPECT_LT(g_ij.dot(rij), 0.0);
  // No direction at r = 0: the gradient is zero, not NaN.
  EXPECT_EQ(TypeParam::grad_w(Vec<d>::Zero(), 0.0, h), Vec<d>::Zero());
}

TEST(WendlandC2, CentralValueMatchesClosedForm) {
  const Real h = 0.012;  // the paper's particle spacing, as a length scale
  EXPECT_DOUBLE_EQ(WendlandC2<2>::w(0.0, h), 7.0 / (4.0 * kPi * h * h));  // paper eq. 28
  EXPECT_DOUBLE_EQ(WendlandC2<3>::w(0.0, h), 21.0 / (16.0 * kPi * h * h * h));
  EXPECT_EQ(WendlandC2<2>::dw_dr(0.0, h), 0.0);
  // q = 1: (1/2)^4 * 3 = 3/16.
  EXPECT_DOUBLE_EQ(WendlandC2<2>::w(h, h), 7.0 / (4.0 * kPi * h * h) * 3.0 / 16.0);
}

TEST(CubicSpline, CentralValueMatchesClosedForm) {
  const Real h = 0.012;
  EXPECT_DOUBLE_EQ(CubicSpline<2>::w(0.0, h), 10.0 / (7.0 * kPi * h * h));
  EXPECT_DOUBLE_EQ(CubicSpline<3>::w(0.0, h), 1.0 / (kPi * h * h * h));
  EXPECT_EQ(CubicSpline<3>::dw_dr(0.0, h), 0.0);
  // q = 1: 1 - 3/2 + 3/4 = 1/4 from the inner branch, (2-1)^3/4 = 1/4 from the outer one.
  EXPECT_DOUBLE_EQ(CubicSpline<3>::w(h, h), 0.25 / (kPi * h * h * h));
}

}  // namespace
}  // namespace crater::sph

// grad_factor is (dW/dr)/r, the form the force loops use; it must agree with dw_dr / r and stay
// finite at r = 0.
template <class Kernel>
void expect_grad_factor_consistent() {
  const crater::Real h = 0.013;
  for (int k = 1; k < 400; ++k) {
    const crater::Real r = 2.0 * h * k / 400.0;
    const crater::Real expected = Kernel::dw_dr(r, h) / r;
    EXPECT_NEAR(Kernel::grad_factor(r, h), expected, 1e-12 * std::abs(expected) + 1e-300)
        << "r/h = " << r / h;
  }
  EXPECT_TRUE(std::isfinite(Kernel::grad_factor(0.0, h)));
  EXPECT_EQ(Kernel::grad_factor(2.0 * h * (1 + 1e-12), h), 0.0);
}

TEST(KernelGradFactor, WendlandC2) {
  expect_grad_factor_consistent<crater::sph::WendlandC2<2>>();
  expect_grad_factor_consistent<crater::sph::WendlandC2<3>>();
}

TEST(KernelGradFactor, CubicSpline) {
  expect_grad_factor_consistent<crater::sph::CubicSpline<2>>();
  expect_grad_factor_consistent<crater::sph::CubicSpline<3>>();
}
