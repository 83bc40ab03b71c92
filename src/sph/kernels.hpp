// SPH smoothing kernels W(r, h), templated on the dimension D (2 = plane strain, 3 = solid).
//
// Every kernel here is a small value type with
//   static constexpr Real support        support radius in units of h (W = 0 for r >= support*h)
//   static Real w(Real r, Real h)         kernel value                         [1/m^D]
//   static Real dw_dr(Real r, Real h)     radial derivative dW/dr (<= 0)        [1/m^(D+1)]
//   static Vec<D> grad_w(rij, r, h)       gradient wrt x_i, rij = x_i - x_j    [1/m^(D+1)]
//   static Real grad_factor(r, h)         (dW/dr)/r, so grad_w = grad_factor*rij [1/m^(D+2)]
// so a hot loop can be templated on the kernel type and stays branch-free (STYLE habit 1).
// q = r/h throughout; h is the smoothing length [m].
#pragma once

#include <numbers>

#include "core/types.hpp"
#include "sph/settings.hpp"  // KernelKind

namespace crater::sph {

namespace detail {

/// \nabla_i W = (dW/dr) r_ij / r with r_ij = x_i - x_j; 0 at r = 0 (the limit for any kernel
/// with dW/dr(0) = 0, as both kernels below have).
template <int D>
inline Vec<D> radial_gradient(const Vec<D>& rij, Real r, Real dw_dr) {
  if (r <= Real(0)) {
    return Vec<D>::Zero();
  }
  return (dw_dr / r) * rij;
}

/// 1/h^D [1/m^D].
template <int D>
inline Real inv_h_pow_d(Real h) {
  if constexpr (D == 2) {
    return Real(1) / (h * h);
  } else {
    return Real(1) / (h * h * h);
  }
}

}  // namespace detail

/// Wendland C2 kernel (Wendland 1995; in SPH: Dehnen & Aly 2012, MNRAS 425, 1068), support 2h:
///   W(q) = \alpha_D (1 - q/2)^4 (2q + 1)   for 0 <= q < 2,   0 otherwise,
///   \alpha_2 = 7 / (4 \pi h^2)    (paper eq. 28),
///   \alpha_3 = 21 / (16 \pi h^3),
///   dW/dr = -(5 \alpha_D / h) q (1 - q/2)^3.
/// Wendland kernels are positive definite in Fourier space, so they do not suffer the pairing
/// instability of the B-splines; that is why the paper (after its refs. 28, 32) uses it.
template <int D>
struct WendlandC2 {
  static_assert(D == 2 || D == 3, "WendlandC2 is defined for D = 2 and D = 3");
  static constexpr int dim = D;
  static constexpr Real support = 2.0;

  /// \alpha_D h^D, the dimensionless normalisation.
  static constexpr Real sigma =
      D == 2 ? Real(7) / (Real(4) * std::numbers::pi) : Real(21) / (Real(16) * std::numbers::pi);

  static Real w(Real r, Real h) {
    const Real q = r / h;
    if (q >= support) {
      return Real(0);
    }
    const Real a = Real(1) - Real(0.5) * q;
    const Real a2 = a * a;
    return sigma * detail::inv_h_pow_d<D>(h) * a2 * a2 * (Real(2) * q + Real(1));
  }

  static Real dw_dr(Real r, Real h) {
    const Real q = r / h;
    if (q >= support) {
      return Real(0);
    }
    const Real a = Real(1) - Real(0.5) * q;
    return -Real(5) * sigma * detail::inv_h_pow_d<D>(h) / h * q * a * a * a;
  }

  static Vec<D> grad_w(const Vec<D>& rij, Real r, Real h) {
    return detail::radial_gradient<D>(rij, r, dw_dr(r, h));
  }

  /// (dW/dr) / r = -(5 \alpha_D / h^2) (1 - q/2)^3, finite at r = 0; the hot loops use
  /// grad_i W = grad_factor * r_ij, which needs no division by r.
  static Real grad_factor(Real r, Real h) {
    const Real inv_h = Real(1) / h;
    const Real q = r * inv_h;
    if (q >= support) return Real(0);
    const Real a = Real(1) - Real(0.5) * q;
    return -Real(5) * sigma * detail::inv_h_pow_d<D>(h) * inv_h * inv_h * a * a * a;
  }
};

/// Cubic B-spline (M4) kernel (Monaghan 1992, Annu. Rev. Astron. Astrophys. 30, 543, eq. 2.6;
/// Monaghan & Lattanzio 1985), support 2h:
///   W(q) = \sigma_D [1 - (3/2) q^2 + (3/4) q^3]   for 0 <= q < 1,
///   W(q) = \sigma_D (1/4) (2 - q)^3               for 1 <= q < 2,   0 otherwise,
///   \sigma_2 = 10 / (7 \pi h^2),   \sigma_3 = 1 / (\pi h^3),
///   dW/dr = (\sigma_D / h) [-3q + (9/4) q^2]  for q < 1,   -(3 \sigma_D / 4h) (2 - q)^2  for 1 <=
///   q < 2.
template <int D>
struct CubicSpline {
  static_assert(D == 2 || D == 3, "CubicSpline is defined for D = 2 and D = 3");
  static constexpr int dim = D;
  static constexpr Real support = 2.0;

  /// \sigma_D h^D, the dimensionless normalisation.
  static constexpr Real sigma =
      D == 2 ? Real(10) / (Real(7) * std::numbers::pi) : Real(1) / std::numbers::pi;

  static Real w(Real r, Real h) {
    const Real q = r / h;
    const Real s = sigma * detail::inv_h_pow_d<D>(h);
    if (q < Real(1)) {
      return s * (Real(1) - Real(1.5) * q * q + Real(0.75) * q * q * q);
    }
    if (q < support) {
      const Real b = Real(2) - q;
      return s * Real(0.25) * b * b * b;
    }
    return Real(0);
  }

  static Real dw_dr(Real r, Real h) {
    const Real q = r / h;
    const Real s = sigma * detail::inv_h_pow_d<D>(h) / h;
    if (q < Real(1)) {
      return s * (-Real(3) * q + Real(2.25) * q * q);
    }
    if (q < support) {
      const Real b = Real(2) - q;
      return -s * Real(0.75) * b * b;
    }
    return Real(0);
  }

  static Vec<D> grad_w(const Vec<D>& rij, Real r, Real h) {
    return detail::radial_gradient<D>(rij, r, dw_dr(r, h));
  }

  /// (dW/dr) / r, finite at r = 0: s (-3 + 9q/4) / h for q < 1, -s (3/4)(2 - q)^2 / (q h)
  /// for 1 <= q < 2, with s = \sigma_D / h^{D+1}.
  static Real grad_factor(Real r, Real h) {
    const Real inv_h = Real(1) / h;
    const Real q = r * inv_h;
    const Real s = sigma * detail::inv_h_pow_d<D>(h) * inv_h * inv_h;
    if (q < Real(1)) return s * (-Real(3) + Real(2.25) * q);
    if (q < support) {
      const Real b = Real(2) - q;
      return -s * Real(0.75) * b * b / q;
    }
    return Real(0);
  }
};

}  // namespace crater::sph
