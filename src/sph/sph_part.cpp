// The SPH part (sph_part_impl.hpp): construction, the step's stages around the force stage
// (stable step, forces, advance, finish_step), the forces of contacts with other parts,
// energies, outflow removal, the neighbour lists, checkpoints, and the factory make_sph_part.
#include "sph/sph_part.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <stdexcept>

#include "neighbors/cell_grid.hpp"
#include "neighbors/pair_radius_list.hpp"
#include "parts/on_ranks.hpp"
#include "sph/kernels.hpp"
#include "sph/sph_part_impl.hpp"
#include "sph/sph_setup.hpp"

namespace crater::sph {
namespace detail {

using fields::kHalo;
using fields::kNone;
using fields::kOutput;
using fields::kRestart;
using fields::kStateRoles;
using parts::to_vec;

template <int D>
SphPart<D>::SphPart(const PartSettings& settings)
    : name_(settings.part.name),
      where_(settings.part.where),
      eos_(settings.eos),
      cfg_(settings.sph),
      spacing_(settings.part.spacing_m),
      rho_material_(settings.rho0_kg_m3),
      gravity_(to_vec<D>(settings.part.domain.gravity_m_s2)),
      domain_lo_(to_vec<D>(settings.part.domain.min_m)),
      domain_hi_(to_vec<D>(settings.part.domain.max_m)),
      outflow_remove_(settings.part.domain.outflow == parts::Outflow::Remove),
      id_(f_.add_integer("id", "1", kStateRoles)),
      x_(f_.add_vector("position", "m", kRestart | kHalo)),
      v_(f_.add_vector("velocity", "m/s", kStateRoles)),
      m_(f_.add_scalar("mass", "kg", kStateRoles)),
      rho_(f_.add_scalar("density", "kg/m^3", kStateRoles)),
      e_(f_.add_scalar("specific_energy", "J/kg", kStateRoles)),
      h_(f_.add_scalar("smoothing_length", "m", kStateRoles)),
      p_(f_.add_scalar("pressure", "Pa", kOutput)),
      c_(f_.add_scalar("sound_speed", "m/s", kOutput)),
      burn_(f_.add_scalar("burn_fraction", "1", kOutput | kRestart | kHalo)),
      light_(f_.add_scalar("lighting_time", "s", kRestart | kHalo)),
      a_(f_.add_vector("acceleration", "m/s^2", kRestart)),
      drho_(f_.add_scalar("density_rate", "kg/m^3/s", kRestart)),
      de_(f_.add_scalar("energy_rate", "W/kg", kRestart)),
      dx_xsph_(f_.add_vector("xsph_velocity", "m/s", kRestart)),
      vh_(f_.add_vector("velocity_half", "m/s", kNone)),
      rhoh_(f_.add_scalar("density_half", "kg/m^3", kNone)),
      eh_(f_.add_scalar("energy_half", "J/kg", kNone)),
      dt_cv_(f_.add_scalar("dt_signal", "s", kNone)),
      omega_(f_.add_scalar("grad_h_omega", "1", kHalo)),
      h_list_(f_.add_scalar("list_smoothing_length", "m", kRestart)),
      h_wanted_(f_.add_scalar("wanted_smoothing_length", "m", kNone)),
      list_reach_(f_.add_scalar("list_reach", "m", kNone)),
      fc_(f_.add_vector("contact_force", "N", kRestart)),
      surface_offset_(f_.add_scalar("contact_surface_offset", "m", kRestart)),
      surface_overlap_(f_.add_scalar("contact_surface_overlap", "m", kRestart)),
      work_external_(f_.add_scalar("work_external", "J", kRestart)) {
  const parts::PartSetup& pc = settings.part;
  const ParticleLattice<D> lattice = particle_lattice<D>(pc, spacing_);
  const std::vector<Vec<D>>& pts = lattice.x;
  const Index n = static_cast<Index>(pts.size());
  f_.resize(n);
  std::fill(surface_offset_.begin(), surface_offset_.end(), Real(-1));  // not touching
  std::fill(omega_.begin(), omega_.end(), Real(1));
  cell_volume_ = std::pow(spacing_, D);
  h0_ = cfg_.h_factor * spacing_;
  burn_model_ = ProgrammedBurn::of(eos_, spacing_, !pc.detonations.empty());

  for (Index i = 0; i < n; ++i) {
    const StartState<D> start = start_state<D>(pc, settings.rho0_kg_m3, pts[i]);
    const Real pitch = lattice.pitch[at(i)];
    id_[i] = i;
    x_[i] = pts[i];
    v_[i] = start.v;
    m_[i] = start.rho * std::pow(pitch, D);
    rho_[i] = start.rho;
    h_[i] = cfg_.h_factor * pitch;
    e_[i] = initial_energy(start.rho, start.pressure);
    light_[i] =
        lighting_time<D>(pc, burn_model_.explosive, burn_model_.detonation_velocity, pts[i]);
  }
  h_max_ = parallel::max_over(n, h0_, [&](Index i) { return h_[i]; });

  // The wall must be as thick as the kernel support of the largest particle, or particles
  // near it see a truncated kernel and too little repulsion.
  const int layers =
      std::max(cfg_.wall_layers,
               static_cast<int>(std::ceil(WendlandC2<D>::support * h_max_ / spacing_ - 1e-9)));
  has_walls_ = !cfg_.walls.empty();
  if (cfg_.wall_no_slip) {
    WallLattice<D> wl = wall_lattice<D>(pc.domain, cfg_.walls, layers, spacing_);
    wall_x_ = std::move(wl.x);
    wall_mirror_ = std::move(wl.mirror);
  }
  const std::size_t nw = wall_x_.size();
  wall_.p.assign(nw, 0);
  wall_.rho.assign(nw, settings.rho0_kg_m3);
  wall_.c.assign(nw, 0);
  wall_.v.assign(nw, Vec<D>::Zero());
  resort((1 + kSkin) * WendlandC2<D>::support * h_max_);
}

template <int D>
parts::StableStep SphPart<D>::stable_step() const {
  // Monaghan & Kos (1999): dt = cfl * min(dt_f, dt_cv), dt_f = sqrt(h/|a|),
  // dt_cv = h / (c + max_j |mu_ij|) (max over neighbours, from the force loop); with the
  // artificial conductivity max_j |mu_ij| becomes max(max_j |mu_ij|, max_j alpha_u v_sig^u_ij),
  // the diffusion's own signal speed (explicit diffusion needs dt <~ h / (alpha_u v_sig^u));
  // with a laminar viscosity also Morris, Fox & Zhu (1997) eq. 12: dt_v = 0.125 h^2 rho / mu.
  parts::StableStep s;
  s.dt_s = kInf;
  const Real mu = cfg_.viscosity_pa_s;
  auto limits = [&](Index i) {
    const Real an = a_[i].norm();
    const Real dt_f = an > 0 ? std::sqrt(h_[i] / an) : kInf;
    const Real dt_v = mu > 0 ? Real(0.125) * h_[i] * h_[i] * rho_[i] / mu : kInf;
    return std::array<Real, 4>{std::min(cfg_.cfl * std::min(dt_f, dt_cv_[i]), dt_v), dt_f, dt_v,
                               an};
  };
  Index limiting = -1;
  for (Index i = 0; i < f_.size(); ++i) {
    if (ghost(i)) continue;
    const Real dt_i = limits(i)[0];
    if (dt_i < s.dt_s || (dt_i == s.dt_s && id_[i] < s.entity_id)) {  // ties: smallest id
      s.dt_s = dt_i;
      s.entity_id = id_[i];
      limiting = i;
    }
  }
  // The reason of the limiting particle alone (a string per particle would cost more than
  // the search).
  if (limiting >= 0) {
    const auto [dt_i, dt_f, dt_v, an] = limits(limiting);
    s.reason = dt_i == dt_v ? fmt::format("viscous limit, mu = {:.3g} Pa s", mu)
               : dt_f < dt_cv_[limiting]
                   ? fmt::format("force criterion, |a| = {:.3g} m/s^2", an)
                   : fmt::format("CFL {} with sound speed {:.4g} m/s", cfg_.cfl, c_[limiting]);
  }
  return spread_.active() ? parts::smallest_step(spread_.comm(), s) : s;
}

template <int D>
void SphPart<D>::compute_forces(Real t) {
  ++state_epoch_;
  time_s_ = t;
  // On ranks the ghosts' state comes from their owners, before anything reads it.
  if (spread_.active()) spread_.refresh(f_, kHalo);
  if (summation()) {
    update_neighbors();
    summation_density();
    if (spread_.active()) spread_.refresh(f_, kHalo);  // their summed rho, h and Omega
  } else {
    update_smoothing_lengths();
  }
  update_neighbors();
  update_eos(t);
  pair_rates();
}

template <int D>
std::optional<parts::Fault> SphPart<D>::check() const {
  const Index n = f_.size();
  // First offending particle in index order (deterministic).
  Index bad = n;
#pragma omp parallel for schedule(static) reduction(min : bad) if (n >= parallel::parallel_min())
  for (Index i = 0; i < n; ++i)
    if (!ghost(i) && !healthy(i)) bad = std::min(bad, i);
  if (bad == n)
    return spread_.active() ? parts::first_fault(spread_.comm(), std::nullopt) : std::nullopt;
  const Index i = bad;
  std::string what;
  if (!outflow_remove_ && !in_domain(i))
    what = fmt::format(
        "particle left the domain at x = ({}) m; enlarge [domain], add walls or set "
        "domain.outflow = \"remove\"",
        fmt::join(x_[i].data(), x_[i].data() + D, ", "));
  else if (!x_[i].allFinite())
    what = fmt::format("non-finite position x = ({}) m",
                       fmt::join(x_[i].data(), x_[i].data() + D, ", "));
  else if (!(rho_[i] > 0))
    what = fmt::format("non-positive density {} kg/m^3", rho_[i]);
  else
    what = fmt::format("non-finite rate or pressure (p = {} Pa, rho = {} kg/m^3, e = {} J/kg)",
                       p_[i], rho_[i], e_[i]);
  const parts::Fault fault{id_[i], what};
  return spread_.active() ? parts::first_fault(spread_.comm(), fault) : fault;
}

// Velocity Verlet with predicted rates: density and energy are kicked like the velocity, so
// the state of time t+dt (x, v, rho, e) is second-order accurate, and the forces at t+dt are
// evaluated with predicted v, rho, e of that time (Springel 2005 uses the same prediction).
template <int D>
void SphPart<D>::advance(Real /*t*/, Real dt) {
  ++state_epoch_;
  const Real half = 0.5 * dt;
  const bool sum_rho = summation();  // the force stage sums the density of t + dt
  const bool gravity = gravity_.squaredNorm() > 0;
  parallel::for_each(f_.size(), [&](Index i) {
    if (ghost(i)) return;
    vh_[i] = v_[i] + half * a_[i];
    rhoh_[i] = rho_[i] + half * drho_[i];
    eh_[i] = e_[i] + half * de_[i];
    x_[i] += dt * (vh_[i] + dx_xsph_[i]);
    if (has_walls_) reflect_at_walls(i);
    v_[i] = vh_[i] + half * a_[i];
    if (!sum_rho) rho_[i] = rhoh_[i] + half * drho_[i];
    e_[i] = eh_[i] + half * de_[i];
    // Work of gravity over the step, with the mid-step velocity.
    if (gravity) work_external_[i] += dt * (m_[i] * gravity_.dot(vh_[i]));
  });
  contact_.moved(dt);
  next_contact_.started();
}

template <int D>
void SphPart<D>::finish_step(Real dt) {
  ++state_epoch_;
  const Real half = 0.5 * dt;
  const bool sum_rho = summation();
  parallel::for_each(f_.size(), [&](Index i) {
    if (ghost(i)) return;
    v_[i] = vh_[i] + half * a_[i];
    if (!sum_rho) rho_[i] = rhoh_[i] + half * drho_[i];
    e_[i] = eh_[i] + half * de_[i];
  });
  next_contact_.finished([&](const auto& f, const auto&) { take_contact(f); });
  if (outflow_remove_) remove_outflow();
}

template <int D>
std::optional<parts::ContactPoints<D>> SphPart<D>::contact_points() const {
  if (radius_epoch_ != state_epoch_ || static_cast<Index>(contact_radius_.size()) != f_.size()) {
    contact_radius_.resize(static_cast<std::size_t>(f_.size()));
    parallel::for_each(
        f_.size(), [&](Index i) { contact_radius_[i] = Real(0.5) * dth_root<D>(m_[i] / rho_[i]); });
    radius_epoch_ = state_epoch_;
  }
  return parts::ContactPoints<D>{.position = lagged_.view(x_),
                                 .velocity = &v_,
                                 .mass = &m_,
                                 .radius = &contact_radius_,
                                 .surface_offset = &surface_offset_,
                                 .surface_overlap = &surface_overlap_,
                                 .id = &id_};
}

template <int D>
void SphPart<D>::set_next_contact_forces(const std::vector<Vec<D>>& force,
                                         const std::vector<AxialVec<D>>& torque) {
  if (static_cast<Index>(force.size()) != f_.size())
    throw std::logic_error("sph: next contact forces for another particle count");
  next_contact_.set(force, torque, [&](const auto& f, const auto&) { take_contact(f); });
}

template <int D>
void SphPart<D>::add_contact_forces(const std::vector<Vec<D>>& force,
                                    const std::vector<AxialVec<D>>& /*torque*/) {
  if (static_cast<Index>(force.size()) != f_.size())
    throw std::logic_error("sph: contact forces for another particle count");
  contact_.settle(
      spread_.active() ? spread_.comm() : parallel::Comm{}, f_.size(),
      [&](Index i) { return vh_[i].dot(fc_[i] + force[i]); }, [&](Index i) { return !ghost(i); });
  parallel::for_each(f_.size(), [&](Index i) {
    fc_[i] = force[i];
    a_[i] += fc_[i] / m_[i];
  });
}

template <int D>
parts::Energies SphPart<D>::energies() const {
  parts::Energies en;
  en.kinetic_j = total([&](Index i) { return 0.5 * m_[i] * v_[i].squaredNorm(); });
  en.internal_j = total([&](Index i) { return m_[i] * e_[i]; });
  en.external_work_j = total([&](Index i) { return work_external_[i]; }, external_work_);
  en.contact_j = -contact_.work_j;
  en.eroded_j = outflow_.energy_j();
  return en;
}

// outflow = "remove" (parts/outflow.hpp): particles beyond the domain box leave the model at
// the end of the step, with the velocity, density and energy of t + dt; their kinetic and
// internal energy goes to eroded_j. The rest keep their order: the same numbers for any
// thread count, and after a restart from this state (which holds the rebuilt lists' skin).
template <int D>
void SphPart<D>::remove_outflow() {
  const Index n = f_.size();
  outflow_.mark(n, [&](Index i) { return in_domain(i); });
  // On ranks every rank marks its own particles and its ghosts (whose positions its owner
  // refreshed at this force stage: every rank agrees on them); the own ones that leave are
  // counted and summed over every rank, by the reproducible sum (one rank's bits anywhere).
  const parallel::Comm one;
  const parallel::Comm& comm = spread_.active() ? spread_.comm() : one;
  const parts::OutflowTally gone = outflow_.tally(comm, n, [&](Index i) { return !ghost(i); });
  if (gone.count == 0) return;
  const parts::Removed removed{
      gone.sum(comm, [&](Index i) { return m_[i]; }),
      gone.sum(comm, [&](Index i) { return 0.5 * m_[i] * v_[i].squaredNorm() + m_[i] * e_[i]; })};
  outflow_.book(name_, "particles", time_s_, gone.count, removed);
  // The leaving particles' work books stay with the part: with the root on ranks, which holds
  // the whole part's (as it holds its reflections).
  const Real left_work = gone.sum(comm, [&](Index i) { return work_external_[i]; });
  if (comm.root()) external_work_ += left_work;
  outflow_.compact(f_);
  spread_.compacted(outflow_.survivors());
  // The rates of the state without them (lists rebuilt, and the particles sorted as at any
  // rebuild: the order of one rank, which a rank's share restricts), the contact forces
  // added as in add_contact_forces: the next half kick owes nothing to a removed particle and
  // the pair terms stay equal and opposite. Without this their pressure work over that half
  // kick went unbooked (1 % of the energy of the gas disk of tests/verification/outflow).
  relist(true);
  pair_rates();
  parallel::for_each(f_.size(), [&](Index i) { a_[i] += fc_[i] / m_[i]; });
}

// Verlet lists (1967) per particle: i's serve h up to h_list_i, a pair is listed when within
// (1 + kSkin) x the support of the larger h_list at the rebuild, and they are kept while no
// support plus twice the largest displacement outgrows that. Re-sorted at rebuilds (locality).
// On ranks the decision is every rank's (the largest over them): the lists are rebuilt at the
// steps of one rank.
template <int D>
void SphPart<D>::update_neighbors() {
  if (!lists_stale()) return;
  relist(true);
}

template <int D>
bool SphPart<D>::lists_stale() const {
  const Index n = f_.size();
  const bool none = skin_.radius() <= 0 || skin_.positions().size() != at(n);  // no lists
  const Real excess = none ? kInf : parallel::max_over(n, -kInf, [&](Index i) {
    return ghost(i) ? -kInf : h_[i] - (1 + kSkin) * h_list_[i];
  });
  const Real moved = none ? 0 : skin_.moved(std::span<const Vec<D>>(x_));
  // Each extreme over every rank's particles, then the test of the extremes: one rank's test.
  return WendlandC2<D>::support * global_max(excess) + 2 * global_max(moved) > 0;
}

// New lists: the smoothing lengths they serve (set_list_h), on ranks the particles moved to their
// owners and the ghosts within reach (fields::Spread), the canonical order (`sort`: a cell order
// by the new lists' reach, ids breaking ties; the order of one rank, which a checkpoint written
// on ranks restores from the positions of the build), then the lists.
template <int D>
void SphPart<D>::relist(bool sort) {
  set_list_h();
  const Real need = WendlandC2<D>::support * h_max_;
  const Real radius = (1 + kSkin) * need;  // the lists' reach, as skin_.built makes it
  if (spread_.active()) {
    // A particle's cost: its pairs on the lists of the last build (1 + row length), or 1.
    std::vector<Real> cost(static_cast<std::size_t>(f_.size()), 1);
    if (list_.size() == f_.size())
      for (Index i = 0; i < f_.size(); ++i)
        cost[at(i)] += static_cast<Real>(list_.of(i).size());
    // The walls' densities this rank averaged under the last lists go to every rank before
    // the particles move: a wall particle may be complete elsewhere under the new ones.
    if (!wall_complete_.empty()) wall_.rho = shared_wall_density();
    spread_.rebuild(f_, x_, id_, halo_reach(radius), cost);
  }
  if (sort) resort(radius);
  skin_.built(std::span<const Vec<D>>(x_), need);
  build_lists();
}

// i's lists serve h_i or more (asked); all the largest within 2x. Over this rank's own
// particles (the ghosts go at the rebuild), the extremes over every rank's.
template <int D>
void SphPart<D>::set_list_h() {
  parallel::for_each(f_.size(), [&](Index i) { h_list_[i] = std::max(h_[i], h_wanted_[i]); });
  const Real lo = -global_max(parallel::max_over(
      f_.size(), -kInf, [&](Index i) { return ghost(i) ? -kInf : -h_list_[i]; }));
  h_max_ = std::max(h_max_, global_max(parallel::max_over(f_.size(), 0.0, [&](Index i) {
                      return ghost(i) ? Real(0) : h_list_[i];
                    })));
  if (h_max_ <= 2 * lo) parallel::for_each(f_.size(), [&](Index i) { h_list_[i] = h_max_; });
}

// Lists at the last rebuild's positions (a restart: the same); wall particles: the largest h.
template <int D>
void SphPart<D>::build_lists() {
  const std::span<const Vec<D>> xb = skin_.positions();
  const Real radius = skin_.radius();
  parallel::for_each(f_.size(), [&](Index i) {  // std::min(radius, NaN) is radius
    list_reach_[i] = std::min(radius, (1 + kSkin) * WendlandC2<D>::support * h_list_[i]);
  });
  neighbors::build_pair_radius_list<D>(xb, std::span<const Real>(list_reach_), list_, levels_);
  if (!wall_x_.empty()) {
    neighbors::build_cross_list<D>(std::span<const Vec<D>>(wall_x_), xb, radius, wall_to_fluid_);
    neighbors::build_cross_list<D>(xb, std::span<const Vec<D>>(wall_x_), radius, fluid_to_wall_);
    if (spread_.active()) mark_complete_walls(xb, radius);
  }
  if (has_walls_ && !cfg_.wall_no_slip) {
    ghosts_.select(xb, radius, cfg_.walls, domain_lo_, domain_hi_);
    ghosts_.place(xb);
    // An image takes its parent's reach: a pair is listed when within the larger of the two,
    // as between two particles (not at the largest reach of all, which a few hot particles set).
    ghost_reach_.resize(static_cast<std::size_t>(ghosts_.size()));
    parallel::for_each(ghosts_.size(), [&](Index g) {
      ghost_reach_[at(g)] = list_reach_[at(ghosts_.parent[at(g)])];
    });
    neighbors::build_cross_radius_list<D>(
        xb, std::span<const Real>(list_reach_), std::span<const Vec<D>>(ghosts_.x),
        std::span<const Real>(ghost_reach_), fluid_to_ghost_, levels_);
  }
}

template <int D>
void SphPart<D>::resort(Real cell_m) {
  const auto order = neighbors::cell_sort_order<D>(  // within a cell by id: canonical
      std::span<const Vec<D>>(x_), cell_m, std::span(id_));
  f_.permute(order);
  spread_.permuted(order);
}

// The checkpoint layout, for both directions (Self: const for writing).
template <int D>
void SphPart<D>::save_state(parts::StateWriter& w) const {
  if (spread_.active()) {
    save_gathered(w);
    return;
  }
  archive(w, *this, f_, skin_, reflections_, max_penetration_, wall_.rho);
}

template <int D>
void SphPart<D>::load_state(parts::StateReader& r) {
  ++state_epoch_;
  archive(r, *this, f_, skin_, reflections_, max_penetration_, wall_.rho);
  if (skin_.radius() > 0) build_lists();
}

#define CRATER_SPH_PART(D)                                                            \
  template SphPart<D>::SphPart(const PartSettings&);                                  \
  template parts::StableStep SphPart<D>::stable_step() const;                         \
  template void SphPart<D>::compute_forces(Real);                                     \
  template std::optional<parts::Fault> SphPart<D>::check() const;                     \
  template void SphPart<D>::advance(Real, Real);                                      \
  template void SphPart<D>::finish_step(Real);                                        \
  template std::optional<parts::ContactPoints<D>> SphPart<D>::contact_points() const; \
  template void SphPart<D>::set_next_contact_forces(const std::vector<Vec<D>>&,       \
                                                    const std::vector<AxialVec<D>>&); \
  template void SphPart<D>::add_contact_forces(const std::vector<Vec<D>>&,            \
                                               const std::vector<AxialVec<D>>&);      \
  template parts::Energies SphPart<D>::energies() const;                              \
  template void SphPart<D>::remove_outflow();                                         \
  template void SphPart<D>::update_neighbors();                                       \
  template bool SphPart<D>::lists_stale() const;                                      \
  template void SphPart<D>::relist(bool);                                             \
  template void SphPart<D>::set_list_h();                                             \
  template void SphPart<D>::build_lists();                                            \
  template void SphPart<D>::resort(Real);                                             \
  template void SphPart<D>::save_state(parts::StateWriter&) const;                    \
  template void SphPart<D>::load_state(parts::StateReader&);
CRATER_SPH_PART(2)
CRATER_SPH_PART(3)
#undef CRATER_SPH_PART

}  // namespace detail

template <int D>
std::unique_ptr<parts::Part<D>> make_sph_part(const PartSettings& settings) {
  return std::make_unique<detail::SphPart<D>>(settings);
}

template std::unique_ptr<parts::Part<2>> make_sph_part<2>(const PartSettings&);
template std::unique_ptr<parts::Part<3>> make_sph_part<3>(const PartSettings&);

}  // namespace crater::sph
