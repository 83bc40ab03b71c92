// The summation density of one particle (density = "summation"; SphPart::summation_density in
// sph_rates.cpp runs it for every particle and rebuilds the lists when one asks for it):
//   rho_i = sum_j m_j W(r_ij, h_i)  over the particle itself, its fluid neighbours, its mirror
//   images and the wall particles, with h_i = h_factor (m_i / rho_i)^(1/D) solved with it
// (Springel & Hernquist 2002, MNRAS 333, 649; Price 2012, J. Comput. Phys. 231, 759, sec. 3):
// Newton on f(h) = rho_sum(h) - m (h_factor / h)^D, f'(h) = sum_j m_j dW/dh + D m (h_factor /
// h)^D / h, dW/dh = -(D W + r dW/dr) / h, from the particle's last h, each step held within
// [h/2, 2h] and below `limit` (the smaller of the cap and the largest h its lists serve). And
// Omega_i = 1 - (dh/drho) sum_j m_j dW/dh, dh/drho = -h / (D rho), of the grad-h pressure terms
// (pair_terms.hpp, gather_pair_grad_h). docs/theory.md section 2 has the equations.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/types.hpp"

namespace crater::sph {

constexpr int kMaxNewton = 30;     // iterations of one particle's h-rho solve
constexpr Real kNewtonTol = 1e-6;  // |rho_sum - rho_h| / rho_h at which it stops
constexpr Real kMinOmega = 0.1;    // the grad-h factor's floor (it nears 0 only for a particle
                                   // with hardly any neighbour)

/// sum_j m_j W(r_j, h) and sum_j m_j dW/dh, gathered one neighbour at a time.
template <class Kernel>
struct KernelSum {
  static constexpr int D = Kernel::dim;
  Real h = 0, reach2 = 0;
  Real sum = 0, dsum_dh = 0;
  explicit KernelSum(Real h_) : h(h_), reach2(Kernel::support * Kernel::support * h_ * h_) {}
  [[gnu::always_inline]] void add(Real r2, Real m) {
    if (r2 >= reach2) return;
    const Real r = std::sqrt(r2);
    const Real w = Kernel::w(r, h);
    sum += m * w;
    dsum_dh -= m * (D * w + r * Kernel::dw_dr(r, h)) / h;
  }
};

/// A particle's solved state: rho and h, the grad-h factor Omega (1 where h is held: at a
/// limit, or variable_h off) and, when the lists held h back below the cap, the h it wants.
struct DensitySolve {
  Real rho = 0, h = 0, omega = 1, want = 0;
};

/// Solves particle of mass m from h_start; sum_at(h) returns its KernelSum at h.
template <class Kernel, class SumAt>
DensitySolve solve_density(Real m, Real h_start, Real limit, Real cap, Real h_factor,
                           bool variable_h, SumAt&& sum_at) {
  constexpr int D = Kernel::dim;
  DensitySolve s;
  Real h = std::min(h_start, limit);
  for (int it = 0; it < kMaxNewton; ++it) {
    const KernelSum<Kernel> k = sum_at(h);
    s.rho = k.sum;
    if (!variable_h) break;
    s.omega = std::max(kMinOmega, 1 + h / (D * k.sum) * k.dsum_dh);
    const Real rho_h = m * std::pow(h_factor / h, D);
    const Real f = k.sum - rho_h;
    if (std::abs(f) <= kNewtonTol * rho_h) break;
    const Real fp = k.dsum_dh + D * rho_h / h;
    // Newton; where f' is not positive (far from the root), the fixed-point step.
    Real next = fp > 0 ? h - f / fp : h_factor * std::pow(m / k.sum, Real(1) / D);
    next = std::clamp(next, Real(0.5) * h, Real(2) * h);
    if (next > limit) {
      if (h >= limit) {
        if (limit < cap) s.want = std::min(cap, next);
        s.omega = 1;
        break;  // held at the limit: the sum of this h stands
      }
      next = limit;
    }
    h = next;
  }
  s.h = h;
  return s;
}

}  // namespace crater::sph
