// The SPH part's force stage (sph_part_impl.hpp): the summation density, the EOS, the wall
// particles' and mirror images' states, and the pair sums of every particle (rates, with the
// pair terms of pair_terms.hpp they inline). The kernel is chosen here (pair_rates,
// summation_density) and the loops over it are member templates of this file alone.
#include <algorithm>
#include <cmath>
#include <span>
#include <variant>

#include "materials/eos/eos.hpp"
#include "sph/kernels.hpp"
#include "sph/sph_part_impl.hpp"

namespace crater::sph::detail {

// The mirror images' positions, velocities and pressures (sph_walls.hpp, Ghosts).
template <int D>
void SphPart<D>::ghost_state() {
  if (ghosts_.empty()) return;
  ghosts_.place(std::span<const Vec<D>>(x_));
  const Vec<D> g = gravity_;
  parallel::for_each(ghosts_.size(), [&](Index k) {
    const Index j = ghosts_.parent[at(k)];
    ghosts_.v[at(k)] = ghosts_.sign[at(k)].cwiseProduct(v_[j]);
    ghosts_.p[at(k)] = p_[j] + rho_[j] * g.dot(ghosts_.x[at(k)] - x_[j]);
  });
}

// The wall and ghost states and the pair sums (rates) of the current state, on the current
// lists.
template <int D>
void SphPart<D>::pair_rates() {
  ghost_state();
  if (cfg_.kernel == KernelKind::WendlandC2) {
    wall_state<WendlandC2<D>>();
    rates<WendlandC2<D>>();
  } else {
    wall_state<CubicSpline<D>>();
    rates<CubicSpline<D>>();
  }
}

// Paper eq. 37, dh/dt = -(h / (D rho)) drho/dt, integrated exactly: h = h_factor (m/rho)^(1/D)
// (= h_factor x spacing in the initial state).
template <int D>
void SphPart<D>::update_smoothing_lengths() {
  if (!cfg_.variable_h) return;
  const Index n = f_.size();
  const Real hf = cfg_.h_factor;
  parallel::for_each(n, [&](Index i) {
    const Real volume = m_[i] / rho_[i];
    h_[i] = hf * (D == 2 ? std::sqrt(volume) : std::cbrt(volume));
  });
  h_max_ = std::max(h0_, global_max(parallel::max_over(n, 0.0, [&](Index i) { return h_[i]; })));
}

template <int D>
void SphPart<D>::summation_density() {
  if (cfg_.kernel == KernelKind::WendlandC2)
    summation_density<WendlandC2<D>>();
  else
    summation_density<CubicSpline<D>>();
}

// density = "summation" (summation.hpp): each particle's rho, h and Omega from its lists.
// A particle that needs a larger h than its lists serve asks for a rebuild, where its lists
// serve twice that h (capped), and the whole pass repeats from the h reached. Each
// particle reads only positions, masses and its own h, in its lists' order: the same numbers
// for any thread count. On ranks each rank solves its own particles (the ghosts' come from their
// owners after the pass, compute_forces), with the largest displacement over every rank's, and
// every rank repeats the pass when one particle anywhere asks for it.
template <int D>
template <class Kernel>
void SphPart<D>::summation_density() {
  const Real hf = cfg_.h_factor;
  const Real inv_d = Real(1) / D;
  for (int pass = 0;; ++pass) {
    const Index n = f_.size();  // on ranks a rebuild moves particles
    const Real moved = global_max(skin_.moved(std::span<const Vec<D>>(x_)));
    if (!ghosts_.empty()) ghosts_.place(std::span<const Vec<D>>(x_));
    const Real wanted = global_max(parallel::max_over(
        n, 0.0,
        [&](Index i) {
          if (ghost(i)) return Real(0);
          const Real cap = kMaxHGrowth * hf * std::pow(m_[i] / rho_material_, inv_d);
          const Real reach_h =
              ((1 + kSkin) * WendlandC2<D>::support * h_list_[i] - 2 * moved) / Kernel::support;
          const DensitySolve s =
              solve_density<Kernel>(m_[i], h_[i], std::min(cap, reach_h), cap, hf, cfg_.variable_h,
                                    [&](Real h) { return kernel_sum<Kernel>(i, h); });
          rho_[i] = s.rho;
          h_[i] = s.h;
          omega_[i] = s.omega;
          h_wanted_[i] = s.want > 0 ? std::min(2 * s.want, cap) : 0;
          return s.want;
        },
        parallel::Cost::heavy));
    if (wanted <= 0 || pass >= 8) break;
    relist(true);
  }
  std::fill(h_wanted_.begin(), h_wanted_.end(), Real(0));
  h_max_ = std::max(h0_, global_max(parallel::max_over(
                             f_.size(), 0.0, [&](Index i) { return ghost(i) ? Real(0) : h_[i]; })));
}

// The kernel sums of particle i at h over itself, its fluid neighbours, its mirror images and
// the wall particles (each list in ascending order).
template <int D>
template <class Kernel>
KernelSum<Kernel> SphPart<D>::kernel_sum(Index i, Real h) const {
  KernelSum<Kernel> k(h);
  k.add(0, m_[i]);
  for (const Index j : list_.of(i))
    k.add((x_[i] - x_[j]).squaredNorm(), m_[j]);
  if (!wall_x_.empty())
    for (const Index w : fluid_to_wall_.of(i))
      k.add((x_[i] - wall_x_[at(w)]).squaredNorm(), wall_.rho[at(w)] * cell_volume_);
  if (!ghosts_.empty())
    for (const Index g : fluid_to_ghost_.of(i))
      k.add((x_[i] - ghosts_.x[at(g)]).squaredNorm(), m_[ghosts_.parent[at(g)]]);
  return k;
}

// Pressure and sound speed from the EOS, p = F p_EOS(rho, e) with the burn fraction F
// (burn.hpp; 1 but for explosives).
template <int D>
void SphPart<D>::update_eos(Real t) {
  const Index n = f_.size();
  std::visit(
      [&](const auto& law) {
        parallel::for_each(
            n,
            [&](Index i) {
              const Real burn = burn_model_.fraction(t, light_[i], burn_[i], rho_[i]);
              burn_[i] = burn;
              const Real p = materials::eos_pressure_of(law, rho_[i], e_[i]);
              p_[i] = burn * p;
              c_[i] = materials::eos_sound_speed_of(law, rho_[i], e_[i], p);
            },
            parallel::Cost::heavy);  // JWL: two exponentials per particle
      },
      eos_);
}

template <int D>
template <class Kernel>
void SphPart<D>::wall_state() {
  if (wall_x_.empty()) return;
  average_wall_state<Kernel, D>(wall_x_, wall_mirror_, wall_to_fluid_,
                                FluidArrays<D>{x_, h_, p_, rho_, c_, v_}, h0_, gravity_,
                                cfg_.wall_no_slip, wall_complete_, wall_);
}

// Particle i and its three kinds of neighbours as the pair terms see them. A wall particle
// has the density of its fluid average on a cell of the wall lattice, and moves with the
// wall (zero velocity) but shows the viscous terms the mirrored fluid velocity; a mirror
// image is its parent with its own position, velocity and pressure.
template <int D>
Centre<D> SphPart<D>::centre(const RateParams& c, Index i) const {
  Centre<D> me;
  me.x = x_[i];
  me.v = v_[i];
  me.h = h_[i];
  me.rho = rho_[i];
  me.c = c_[i];
  me.p = p_[i];
  me.e = e_[i];
  me.inv_rho = 1 / me.rho;
  me.r_tensile = artificial_pressure(c.eps_tensile, me.p, me.rho);
  if (summation()) me.p_omega = me.p / (omega_[i] * me.rho * me.rho);
  return me;
}

template <int D>
Neighbour<D> SphPart<D>::fluid_neighbour(const Vec<D>& rij, Index j) const {
  return {.rij = rij,
          .m = m_[j],
          .rho = rho_[j],
          .p = p_[j],
          .c = c_[j],
          .e = e_[j],
          .v = v_[j],
          .v_visc = v_[j],
          .wall = false};
}

template <int D>
Neighbour<D> SphPart<D>::wall_neighbour(const Vec<D>& rij, Index w) const {
  const auto k = at(w);
  return {.rij = rij,
          .m = wall_.rho[k] * cell_volume_,
          .rho = wall_.rho[k],
          .p = wall_.p[k],
          .c = wall_.c[k],
          .v = Vec<D>::Zero(),
          .v_visc = wall_.v[k],
          .wall = true};
}

template <int D>
Neighbour<D> SphPart<D>::ghost_neighbour(const Vec<D>& rij, Index g) const {
  const auto k = at(g);
  const Index j = ghosts_.parent[k];
  return {.rij = rij,
          .m = m_[j],
          .rho = rho_[j],
          .p = ghosts_.p[k],
          .c = c_[j],
          .e = e_[j],
          .v = ghosts_.v[k],
          .v_visc = ghosts_.v[k],
          .wall = false};
}

// A neighbour as the grad-h terms see it: with its smoothing length and p / (Omega rho^2)
// (a wall particle: h0 and Omega = 1).
template <int D>
Neighbour<D> SphPart<D>::with_grad_h(Neighbour<D> n, Real h, Real omega) {
  n.h = h;
  n.p_omega = n.p / (omega * n.rho * n.rho);
  return n;
}

// The rates of every particle: the pair terms (pair_terms.hpp, gather_pair) over its fluid
// neighbours, then its wall particles, then the mirror images, each list in ascending order.
template <int D>
template <class Kernel>
void SphPart<D>::rates() {
  const Index n = f_.size();
  const RateParams c{.alpha = cfg_.av_alpha,
                     .beta = cfg_.av_beta,
                     .viscosity_pa_s = cfg_.viscosity_pa_s,
                     .eps_xsph = cfg_.xsph_epsilon,
                     .eps_tensile = cfg_.tensile_epsilon,
                     .alpha_u = cfg_.conductivity_alpha,
                     .spacing_m = spacing_};
  const Vec<D> g = gravity_;
  const bool walls = !wall_x_.empty();
  const bool ghosts = !ghosts_.empty();
  const bool grad_h = summation();
  parallel::for_each(
      n,
      [&](Index i) {
        if (ghost(i)) return;  // its owner's
        const Centre<D> me = centre(c, i);
        PairSums<D> s;
        if (grad_h) {
          for (const Index j : list_.of(i))
            gather_pair_grad_h<Kernel>(
                c, me, with_grad_h(fluid_neighbour(me.x - x_[j], j), h_[j], omega_[j]), s);
          if (walls)
            for (const Index w : fluid_to_wall_.of(i))
              gather_pair_grad_h<Kernel>(
                  c, me, with_grad_h(wall_neighbour(me.x - wall_x_[at(w)], w), h0_, 1), s);
          if (ghosts)
            for (const Index img : fluid_to_ghost_.of(i)) {
              const Index j = ghosts_.parent[at(img)];
              gather_pair_grad_h<Kernel>(
                  c, me,
                  with_grad_h(ghost_neighbour(me.x - ghosts_.x[at(img)], img), h_[j], omega_[j]),
                  s);
            }
        } else {
          for (const Index j : list_.of(i)) {
            const Vec<D> rij = me.x - x_[j];
            const PairKernel<D> k = pair_kernel<Kernel>(rij, me.h, h_[j]);
            if (k.within) gather_pair<Kernel>(c, me, fluid_neighbour(rij, j), k, s);
          }
          if (walls)
            for (const Index w : fluid_to_wall_.of(i)) {
              const Vec<D> rij = me.x - wall_x_[at(w)];
              const PairKernel<D> k = pair_kernel<Kernel>(rij, me.h, h0_);
              if (k.within) gather_pair<Kernel>(c, me, wall_neighbour(rij, w), k, s);
            }
          if (ghosts)
            for (const Index img : fluid_to_ghost_.of(i)) {
              const Vec<D> rij = me.x - ghosts_.x[at(img)];
              const PairKernel<D> k = pair_kernel<Kernel>(rij, me.h, h_[ghosts_.parent[at(img)]]);
              if (k.within) gather_pair<Kernel>(c, me, ghost_neighbour(rij, img), k, s);
            }
        }
        a_[i] = s.acc + g;
        drho_[i] = me.rho * s.drho;
        de_[i] = s.de;
        dx_xsph_[i] = c.eps_xsph * s.xsph;
        dt_cv_[i] = me.h / (me.c + std::max(s.mu_max, s.vsig_u_max));
      },
      parallel::Cost::heavy);  // a particle's sum over its neighbours
}

#define CRATER_SPH_RATES(D)                             \
  template void SphPart<D>::ghost_state();              \
  template void SphPart<D>::pair_rates();               \
  template void SphPart<D>::update_smoothing_lengths(); \
  template void SphPart<D>::summation_density();        \
  template void SphPart<D>::update_eos(Real);
CRATER_SPH_RATES(2)
CRATER_SPH_RATES(3)
#undef CRATER_SPH_RATES

}  // namespace crater::sph::detail
