// The pair terms of the SPH rates, one named step each, for particle i and one neighbour j (a
// fluid particle, a fixed wall particle or a mirror image behind a free-slip wall). The rates
// (SphPart::rates, sph_rates.cpp) gather them in this order for each neighbour:
//   pair_kernel           r_ij, hbar = (h_i + h_j)/2, grad_i W_ij (nothing beyond the support)
//   relative_motion       v_ij and mu_ij = hbar v_ij . r_ij / (r_ij^2 + 0.01 hbar^2)
//   monaghan_viscosity    Pi_ij = (-alpha cbar mu + beta mu^2) / rhobar for v_ij . r_ij < 0
//   tensile_correction    R_ij f_ij^4 (Monaghan 2000), where a pressure is negative
//   pressure_acceleration -(V_j (p_i + p_j)/rho_i + m_j (Pi_ij + R_ij f^4)) grad_i W_ij (eq. 34)
//   continuity_rate       V_j v_ij . grad_i W_ij (eq. 32; times rho_i once summed)
//   energy_rate           (V_j p_i/rho_i + 1/2 m_j Pi_ij) v_ij . grad_i W_ij (wall: all of it)
//   physical_viscosity    Lo & Shao (2002), paper eq. 36, and its heating
//   artificial_conductivity  m_j alpha_u v_sig^u (e_i - e_j) / rhobar r_hat . grad_i W_ij (Price
//                         2008), a heat flux between the pair; off by default
//   xsph_velocity         -m_j / rhobar W_ij v_ij (Monaghan 1989)
// (gather_pair_grad_h: the same steps with the summation density's grad-h pressure and energy
// terms in place of pressure_acceleration and energy_rate.)
// The equations with their sources are in sph_part_impl.hpp's header and docs/theory.md. Every step
// is inline and forced so (always_inline): the gather is the hot loop of an SPH run, and the
// steps must cost what the one loop body they replace did. Each step keeps the arithmetic and
// its order of the loop it came from (bit-identical results).
#pragma once

#include <algorithm>
#include <cmath>

#include "core/types.hpp"

namespace crater::sph {

/// Constants of the pair terms ([parts.sph] numerics and the lattice pitch).
struct RateParams {
  Real alpha = 0, beta = 0;  // Monaghan artificial viscosity
  Real viscosity_pa_s = 0;   // physical (dynamic) viscosity; 0: off
  Real eps_xsph = 0;         // XSPH epsilon; 0: off
  Real eps_tensile = 0;      // tensile-correction epsilon; 0: off
  Real alpha_u = 0;          // Price (2008) artificial conductivity alpha_u; 0: off
  Real spacing_m = 0;        // reference pitch of the tensile correction's W(dp)
};

/// Monaghan (2000) artificial pressure of a particle, R = eps |p| / rho^2 where p < 0, else 0.
[[gnu::always_inline]] inline Real artificial_pressure(Real eps_tensile, Real p, Real rho) {
  return p < 0 ? eps_tensile * -p / (rho * rho) : 0.0;
}

/// Particle i, the centre of the gather, as its sums see it (read once per particle).
template <int D>
struct Centre {
  Vec<D> x, v;
  Real h = 0, rho = 0, c = 0, p = 0;
  Real e = 0;          // specific internal energy [J/kg]
  Real inv_rho = 0;    // 1 / rho
  Real r_tensile = 0;  // artificial_pressure of i
  Real p_omega = 0;    // p / (Omega rho^2), the grad-h pressure factor (summation density)
};

/// One neighbour j within the kernel support: r_ij = x_i - x_j, its state, the velocity the viscous
/// terms see (a wall's mirrored fluid velocity; else v_j) and whether it is a fixed wall particle,
/// which cannot take its share of the pressure work (particle i books all of it, and kinetic plus
/// internal energy stays conserved). e is its specific internal energy (a mirror image: its
/// parent's; a wall particle has none, and the conductivity skips it).
template <int D>
struct Neighbour {
  Vec<D> rij;
  Real m = 0, rho = 0, p = 0, c = 0, e = 0;
  Vec<D> v, v_visc;
  bool wall = false;
  Real h = 0, p_omega = 0;  // smoothing length and p / (Omega rho^2) (gather_pair_grad_h only)
};

/// The sums of particle i over its neighbours.
template <int D>
struct PairSums {
  Vec<D> acc = Vec<D>::Zero(), xsph = Vec<D>::Zero();
  Real drho = 0, de = 0;
  Real mu_max = 0;      // max_j |mu_ij|, for the CFL step
  Real vsig_u_max = 0;  // max_j alpha_u v_sig^u_ij, the conductivity's signal speed, ditto
};

/// Kernel quantities of a pair: within the support of hbar = (h_i + h_j)/2 or not; if so, r,
/// grad_i W_ij = W'(r, hbar)/r r_ij and the mu denominator's regulariser 0.01 hbar^2.
template <int D>
struct PairKernel {
  bool within = false;
  Real r2 = 0, hbar = 0, r = 0, eta2 = 0;
  Vec<D> gw;
};

template <class Kernel, int D>
[[gnu::always_inline]] inline PairKernel<D> pair_kernel(const Vec<D>& rij, Real hi, Real hj) {
  PairKernel<D> k;
  k.r2 = rij.squaredNorm();
  k.hbar = 0.5 * (hi + hj);
  if (k.r2 >= Kernel::support * Kernel::support * k.hbar * k.hbar) return k;
  k.within = true;
  k.r = std::sqrt(k.r2);
  k.gw = Kernel::grad_factor(k.r, k.hbar) * rij;
  k.eta2 = 0.01 * k.hbar * k.hbar;
  return k;
}

/// Relative velocity v_ij, the viscous one (v_i - v_visc_j), and mu_ij of the latter.
template <int D>
struct Approach {
  Vec<D> vij, vij_visc;
  Real vdotr = 0;  // v_ij_visc . r_ij (< 0: approaching)
  Real mu = 0;
};

template <int D>
[[gnu::always_inline]] inline Approach<D> relative_motion(const Centre<D>& i, const Neighbour<D>& j,
                                                          const PairKernel<D>& k) {
  Approach<D> a;
  a.vij = i.v - j.v;
  a.vij_visc = i.v - j.v_visc;
  a.vdotr = a.vij_visc.dot(j.rij);
  a.mu = k.hbar * a.vdotr / (k.r2 + k.eta2);
  return a;
}

/// Monaghan (1992) artificial viscosity Pi_ij [m^5/(kg s^2)], on approaching pairs only.
template <int D>
[[gnu::always_inline]] inline Real monaghan_viscosity(const RateParams& c, const Centre<D>& i,
                                                      const Neighbour<D>& j, const Approach<D>& a) {
  if (!(a.vdotr < 0)) return 0;
  const Real cbar = 0.5 * (i.c + j.c);
  const Real rhobar = 0.5 * (i.rho + j.rho);
  return (-c.alpha * cbar * a.mu + c.beta * a.mu * a.mu) / rhobar;
}

/// Monaghan (2000) tensile correction R_ij f_ij^4, f_ij = W(r, hbar) / W(dp, hbar), R_ij =
/// R_i + R_j (artificial_pressure); 0 where both pressures are non-negative or it is off.
template <class Kernel, int D>
[[gnu::always_inline]] inline Real tensile_correction(const RateParams& c, const Centre<D>& i,
                                                      const Neighbour<D>& j,
                                                      const PairKernel<D>& k) {
  if (!(c.eps_tensile > 0)) return 0;
  const Real rj = artificial_pressure(c.eps_tensile, j.p, j.rho);
  if (!(i.r_tensile + rj > 0)) return 0;
  const Real f = Kernel::w(k.r, k.hbar) / Kernel::w(c.spacing_m, k.hbar);
  const Real f2 = f * f;
  return (i.r_tensile + rj) * f2 * f2;
}

/// Paper eq. 34's pair term without its sign: (V_j (p_i + p_j)/rho_i + m_j (Pi + R f^4))
/// grad_i W_ij [m/s^2], which the acceleration loses.
template <int D>
[[gnu::always_inline]] inline Vec<D> pressure_acceleration(const Centre<D>& i,
                                                           const Neighbour<D>& j,
                                                           const PairKernel<D>& k, Real vol_j,
                                                           Real visc, Real tensile) {
  return (vol_j * (i.p + j.p) * i.inv_rho + j.m * (visc + tensile)) * k.gw;
}

/// Paper eq. 32's pair term over rho_i, V_j v_ij . grad_i W_ij [1/s]. At a wall the density
/// sees the wall's own velocity (zero), as in Adami et al.; mirroring the fluid velocity there
/// instead held shocked gas better in a shock tube but pushed a dam-break surge into the floor
/// (tests/verification/sph_*).
[[gnu::always_inline]] inline Real continuity_rate(Real vol_j, Real vdotgw) {
  return vol_j * vdotgw;
}

/// The energy equation's pair term [W/kg]: (V_j p_i/rho_i + 1/2 m_j Pi_ij) v_ij . grad_i W_ij,
/// the pressure and viscous work balancing the momentum equation's pair by pair; against a
/// wall particle i books the whole pair's work, V_j (p_i + p_j)/rho_i and m_j Pi_ij.
template <int D>
[[gnu::always_inline]] inline Real energy_rate(const Centre<D>& i, const Neighbour<D>& j,
                                               Real vol_j, Real visc, Real vdotgw) {
  return (vol_j * (j.wall ? i.p + j.p : i.p) * i.inv_rho + (j.wall ? 1.0 : 0.5) * j.m * visc) *
         vdotgw;
}

/// Paper eq. 36 (Lo & Shao 2002) with equal viscosities: the acceleration m_j k v_ij_visc,
/// k = 2 mu r_ij . grad_i W_ij / (rho_i rho_j (r^2 + eta^2)) <= 0 (r . grad W <= 0), and the
/// heating, which equals the work the viscous force takes out (v_ij . v_ij_visc: |v_ij|^2 for
/// particle pairs, v_i . (v_i - v_mirror) at a no-slip wall).
template <int D>
struct ViscousTerms {
  Vec<D> acc;
  Real heating = 0;  // subtracted from de/dt
};

template <int D>
[[gnu::always_inline]] inline ViscousTerms<D> physical_viscosity(const RateParams& c,
                                                                 const Centre<D>& i,
                                                                 const Neighbour<D>& j,
                                                                 const PairKernel<D>& k,
                                                                 const Approach<D>& a) {
  const Real kv = 2 * c.viscosity_pa_s * j.rij.dot(k.gw) / (i.rho * j.rho * (k.r2 + k.eta2));
  ViscousTerms<D> t;
  t.acc = j.m * kv * a.vij_visc;
  t.heating = (j.wall ? 1.0 : 0.5) * j.m * kv * a.vij.dot(a.vij_visc);
  return t;
}

/// Price (2008) artificial thermal conductivity: the heat particle i gains from j [W/kg],
///   de_i/dt += m_j alpha_u v_sig^u (e_i - e_j) / rhobar r_hat_ij . grad_i W_ij,
///   v_sig^u = sqrt(|p_i - p_j| / rhobar),   rhobar = (rho_i + rho_j)/2,
/// with r_hat_ij . grad_i W_ij = dW/dr(r, hbar) <= 0: heat flows from the hotter particle to the
/// colder. Every factor but (e_i - e_j) is symmetric in the pair, so m_i de_i/dt = -m_j
/// de_j/dt and the internal energy only moves (total energy conserved pair by pair). The
/// pressure-jump signal speed (Price's choice without gravity) is non-zero only between
/// neighbours of different pressure: it smooths e across a contact discontinuity while the
/// pressure there is out of balance (the shock tube's blip) and leaves smooth flow alone. A
/// fixed wall particle cannot take heat (adiabatic wall): 0 against it. Returns the heat and
/// alpha_u v_sig^u.
struct HeatFlux {
  Real heat = 0;  // added to de_i/dt [W/kg]
  Real vsig = 0;  // alpha_u v_sig^u [m/s], a signal speed of the stable step
};

template <int D>
[[gnu::always_inline]] inline HeatFlux artificial_conductivity(const RateParams& c,
                                                               const Centre<D>& i,
                                                               const Neighbour<D>& j,
                                                               const PairKernel<D>& k) {
  HeatFlux f;
  if (j.wall || !(k.r > 0)) return f;
  const Real rhobar = 0.5 * (i.rho + j.rho);
  f.vsig = c.alpha_u * std::sqrt(std::abs(i.p - j.p) / rhobar);
  const Real dwdr = k.gw.dot(j.rij) / k.r;  // r_hat_ij . grad_i W_ij
  f.heat = j.m * f.vsig * (i.e - j.e) / rhobar * dwdr;
  return f;
}

/// XSPH (Monaghan 1989) pair term without epsilon and sign: m_j / rhobar W_ij v_ij [m/s].
template <class Kernel, int D>
[[gnu::always_inline]] inline Vec<D> xsph_velocity(const Centre<D>& i, const Neighbour<D>& j,
                                                   const PairKernel<D>& k, const Approach<D>& a) {
  return (j.m / (0.5 * (i.rho + j.rho))) * Kernel::w(k.r, k.hbar) * a.vij;
}

/// The terms that are off by default, for both forms of the pair terms, in the order listed
/// above: the laminar viscosity, the conductivity and XSPH, each when on.
template <class Kernel, int D>
[[gnu::always_inline]] inline void optional_terms(const RateParams& c, const Centre<D>& i,
                                                  const Neighbour<D>& j, const PairKernel<D>& k,
                                                  const Approach<D>& a, PairSums<D>& s) {
  if (c.viscosity_pa_s > 0) {
    const ViscousTerms<D> vt = physical_viscosity(c, i, j, k, a);
    s.acc += vt.acc;
    s.de -= vt.heating;
  }
  if (c.alpha_u > 0) {
    const HeatFlux hf = artificial_conductivity(c, i, j, k);
    s.de += hf.heat;
    s.vsig_u_max = std::max(s.vsig_u_max, hf.vsig);
  }
  if (c.eps_xsph > 0) s.xsph -= xsph_velocity<Kernel>(i, j, k, a);
}

/// The pair terms of neighbour j, found within the support by pair_kernel (k), added to
/// particle i's sums in the order listed above. The caller tests the support first and reads
/// the rest of the neighbour's state only then (most list candidates lie beyond it).
template <class Kernel, int D>
[[gnu::always_inline]] inline void gather_pair(const RateParams& c, const Centre<D>& i,
                                               const Neighbour<D>& j, const PairKernel<D>& k,
                                               PairSums<D>& s) {
  const Approach<D> a = relative_motion(i, j, k);
  s.mu_max = std::max(s.mu_max, std::abs(a.mu));
  const Real visc = monaghan_viscosity(c, i, j, a);
  const Real tensile = tensile_correction<Kernel>(c, i, j, k);
  const Real vol_j = j.m / j.rho;
  const Real vdotgw = a.vij.dot(k.gw);
  s.acc -= pressure_acceleration(i, j, k, vol_j, visc, tensile);
  s.drho += continuity_rate(vol_j, vdotgw);
  s.de += energy_rate(i, j, vol_j, visc, vdotgw);
  optional_terms<Kernel>(c, i, j, k, a, s);
}

/// The pair terms with the summation density's own pressure terms (density = "summation";
/// Springel & Hernquist 2002, MNRAS 333, 649; Price 2012, J. Comput. Phys. 231, 759, eqs.
/// 34-35): with P_i = p_i / (Omega_i rho_i^2), Omega_i = 1 - (dh_i/drho_i) sum_k m_k
/// dW_ik(h_i)/dh_i, each particle's kernel at its own h,
///   d v_i/dt -= m_j (P_i grad_i W_ij(h_i) + P_j grad_i W_ij(h_j)) + m_j (Pi_ij + R f^4) grad_i
///   W_ij(hbar) d e_i/dt += m_j P_i v_ij . grad_i W_ij(h_i) + 1/2 m_j Pi_ij v_ij . grad_i
///   W_ij(hbar)
/// (a fixed wall particle: i books the whole pair's work, m_j v_ij . (P_i grad W(h_i) + P_j
/// grad W(h_j)) and m_j Pi_ij v_ij . grad W). Summed over the pairs the pressure work and the
/// internal energy's gain cancel exactly, as in gather_pair. The viscous terms, conductivity,
/// XSPH and the continuity rate (written, not integrated) keep hbar. A pair interacts within the
/// support of the larger h.
template <class Kernel, int D>
[[gnu::always_inline]] inline void gather_pair_grad_h(const RateParams& c, const Centre<D>& i,
                                                      const Neighbour<D>& j, PairSums<D>& s) {
  const Real r2 = j.rij.squaredNorm();
  const Real hmax = std::max(i.h, j.h);
  if (r2 >= Kernel::support * Kernel::support * hmax * hmax) return;
  const Real r = std::sqrt(r2);
  const Vec<D> gwi = Kernel::grad_factor(r, i.h) * j.rij;
  const Vec<D> gwj = Kernel::grad_factor(r, j.h) * j.rij;
  PairKernel<D> k;
  k.r2 = r2;
  k.r = r;
  k.hbar = 0.5 * (i.h + j.h);
  k.eta2 = 0.01 * k.hbar * k.hbar;
  k.within = r2 < Kernel::support * Kernel::support * k.hbar * k.hbar;
  k.gw = k.within ? Vec<D>(Kernel::grad_factor(r, k.hbar) * j.rij) : Vec<D>(Vec<D>::Zero());
  const Approach<D> a = relative_motion(i, j, k);
  s.mu_max = std::max(s.mu_max, std::abs(a.mu));
  const Real visc = k.within ? monaghan_viscosity(c, i, j, a) : 0.0;
  const Real tensile = k.within ? tensile_correction<Kernel>(c, i, j, k) : 0.0;
  const Vec<D> gp = i.p_omega * gwi + j.p_omega * gwj;
  const Real vdotgw = a.vij.dot(k.gw);
  s.acc -= j.m * gp + j.m * (visc + tensile) * k.gw;
  s.drho += continuity_rate(j.m / j.rho, vdotgw);
  s.de += j.wall ? j.m * (a.vij.dot(gp) + visc * vdotgw)
                 : j.m * (i.p_omega * a.vij.dot(gwi) + 0.5 * visc * vdotgw);
  if (!k.within) return;
  optional_terms<Kernel>(c, i, j, k, a, s);
}

}  // namespace crater::sph
