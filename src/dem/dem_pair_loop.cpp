// The DEM part's force stage (dem_part_impl.hpp): pair_pass over the owned pairs, grain_pass
// over the grains (received shares, rigid and absorbing walls, bonds kept, local damping). The
// hot loops and everything they inline (the contact law, prepare_contact, finish_contact) stay
// in this one translation unit.
#include <Eigen/Geometry>  // cross products of 3D contact laws

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <variant>

#include "dem/dem_part_impl.hpp"
#include "dem/laws/local_damping.hpp"

namespace crater::dem::detail {
namespace {

// pair_pass's candidates, per thread, built once (a local array would zero its entries for
// every block); of this file alone (internal linkage: the cheapest thread-local access).
template <class Candidate, int N>
thread_local std::array<Candidate, N> scan_candidates;

}  // namespace

template <int D>
void DemPart<D>::compute_forces(Real t) {
  begin_forces(t);
  parallel::for_each_block(f_.size(), kPairBlock,
                           [&](Index first, Index /*last*/) { force_block(first / kPairBlock); });
  end_forces();
}

template <int D>
Index DemPart<D>::begin_forces(Real t) {
  time_s_ = t;
  if (comm_) refresh_ghosts();
  update_neighbors();
  const Index n = f_.size();
  overflow_ = n;
  bond_lost_ = n;
  unhealthy_ = n;
  // A frame's stress reads every pair's force from the pair cache, which one thread otherwise
  // leaves unwritten (scatter_: the same forces, bit for bit); end_forces() restores it.
  scatter_kept_ = scatter_;
  if (stress_step_) scatter_ = false;
  return (n + kPairBlock - 1) / kPairBlock;
}

// Owned pairs of the grains [b kPairBlock, (b + 1) kPairBlock): their forces, the grains' tallies.
template <int D>
void DemPart<D>::force_block(Index block) {
  const Index first = block * kPairBlock;
  const Index last = std::min(f_.size(), first + kPairBlock);
  const Real dt = contact_.last_dt_s;  // the step just taken
  std::visit([&]<class Law>(const LawPair<Law>& laws) { pair_pass<Law>(first, last, dt, laws); },
             laws_);
}

template <int D>
void DemPart<D>::end_forces() {
  const Index n = f_.size();
  const Real dt = contact_.last_dt_s;
  std::visit(
      [&]<class Law>(const LawPair<Law>& laws) {
        // A frame's stage sums the walls' stress moments in an instance of grain_pass of its
        // own: the other steps' has no trace of them.
        // Ghosts are their owners' to move.
        // A ghost's bond slots hold the bonds with this rank's grains that the pairs above
        // wrote (the others are its owner's); the rest are emptied.
        const bool bonds = !bond_partner_new_.empty();
        if (stress_step_)
          parallel::for_each(n, [&](Index i) {
            if (!ghost(i))
              grain_pass<Law, true>(i, dt, laws);
            else if (bonds)
              close_ghost_bond_slots(i);
          });
        else
          parallel::for_each(n, [&](Index i) {
            if (!ghost(i))
              grain_pass<Law, false>(i, dt, laws);
            else if (bonds)
              close_ghost_bond_slots(i);
          });
      },
      laws_);
  measure_walls();
  scatter_ = scatter_kept_;
  if (stress_step_) grain_stresses();
  stress_current_ = std::exchange(stress_step_, false);
  // Bonds of this step become last step's (contact histories are updated in place).
  bond_partner_.swap(bond_partner_new_);
  bond_.swap(bond_new_);
  // The energy taken out over the last step went to the grains' books (grain_pass). The bonds
  // that broke are counted by the grains that owned them, here and on the other ranks (an
  // integer sum: exact in any order).
  if (bonded_) {  // on every rank, even one that holds none of the part's grains now
    const auto breaks = parallel::deterministic_sum<std::int64_t>(n, [&](Index i) {
      return ghost(i) ? std::int64_t{0} : static_cast<std::int64_t>(bond_breaks_[i]);
    });
    bonds_broken_ += static_cast<Real>(comm_ ? comm_->sum(breaks) : breaks);
  }
}

// Slot of the bond between `owner` and `partner` (last step's buffer), or -1.
template <int D>
inline int DemPart<D>::find_bond(Index owner, std::int64_t partner) const {
  if (bond_partner_.empty()) return -1;
  const std::size_t base = static_cast<std::size_t>(owner) * kMaxContacts;
  for (int k = 0; k < kMaxContacts; ++k) {
    const std::int64_t p = bond_partner_[base + static_cast<std::size_t>(k)];
    if (p == partner) return k;
    if (p == kNoContact) break;
  }
  return -1;
}

// The contact force with the friction of paper section III-C at this contact's strain rate
// |v_n| / (r_1 + r_2) (rate_dependent_friction.hpp; a wall: r_2 = 0). mu_dyn >= mu_s, and mu
// acts only where the Coulomb limit decides the tangential force (ContactForce::limited): the
// force is taken first at a bound just below mu_s (tan(atan(mu_s)) may round below mu_s), and
// only a contact that reaches it pays for mu_dyn's logarithm and tangent. The result is the
// force at mu_dyn, bit for bit: below the limit it does not depend on mu.
template <int D>
template <class Law>
inline ContactForce<D> DemPart<D>::rate_contact(typename Law::Params p,
                                                const RateDependentFriction& rate,
                                                const ContactGeometry<D>& g,
                                                const RelativeVelocity<D>& rel,
                                                const PreparedContact<D>& prep, Real dt, Real r1,
                                                Real r2) const {
  if (!cfg_.rate_dependent_friction) return finish_contact<D, Law>(p, g, rel, prep, dt);
  const Real strain_rate = contact_strain_rate(rel.normal, r1, r2);
  // beta >= 0 (the schema) and the static angle below the cap: mu_dyn >= tan(phi_s).
  if (strain_rate > rate.reference_strain_rate &&
      rate.static_angle_rad < kMaxDynamicFrictionAngle) {
    p.friction = rate.static_friction * Real(1 - 1e-12);
    const ContactForce<D> below = finish_contact<D, Law>(p, g, rel, prep, dt);
    if (!below.limited) return below;
  }
  p.friction = dynamic_friction_coefficient(rate, strain_rate);
  return finish_contact<D, Law>(p, g, rel, prep, dt);
}

// Counts a live contact of grain i (kMaxContacts at most: the packed history's capacity).
template <int D>
inline void DemPart<D>::count_contact(Index i, PairTally& tally) {
  if (tally.slots == kMaxContacts) {
#pragma omp critical(crater_dem_overflow)
    overflow_ = std::min(overflow_, i);
    return;
  }
  ++tally.slots;
}

template <int D>
template <class Law>
inline void DemPart<D>::pair_pass(Index first, Index last, Real dt, const LawPair<Law>& laws) {
  for (Index i = first; i < last; ++i)
    tally_[static_cast<std::size_t>(i)] = PairTally{};
  const bool bonds = !bond_partner_.empty();
  const Index end = pair_begin_[static_cast<std::size_t>(last)];
  std::array<Index, kScanChunk> near, owner_of;
  std::array<Candidate<Law>, kScanChunk>& cand = scan_candidates<Candidate<Law>, kScanChunk>;
  Index owner = first;
  for (Index chunk = pair_begin_[static_cast<std::size_t>(first)]; chunk < end;
       chunk += kScanChunk) {
    const Index stop = std::min(end, chunk + kScanChunk);
    int count = 0;
    for (Index pi = chunk; pi < stop; ++pi) {
      while (pi >= pair_begin_[static_cast<std::size_t>(owner) + 1])
        ++owner;
      const auto k = static_cast<std::size_t>(pi);
      const Index j = pair_j_[k];
      const Real reach = r_[owner] + r_[j];
      // Bonded parts look each pair's bond up first (pair_law).
      const bool close = bonds || (x_[owner] - x_[j]).squaredNorm() <= reach * reach * kTouchMargin;
      near[static_cast<std::size_t>(count)] = pi;
      owner_of[static_cast<std::size_t>(count)] = owner;
      count += close;
      // Rarely true (a contact that just ended): a well-predicted branch, unlike `close`.
      if (!close & (cache_.flags[k] != 0)) clear_pair(k, cache_.flags[k]);
    }
    for (int c = 0; c < count; ++c) {
      const auto at = static_cast<std::size_t>(c);
      const Index i = owner_of[at];
      const Index j = pair_j_[static_cast<std::size_t>(near[at])];
      cand[at].g = sphere_sphere_geometry<D>(x_[i], r_[i], x_[j], r_[j]);
      cand[at].prep = prepare_contact<D, Law>(laws.grain, cand[at].g, effective_mass(m_[i], m_[j]),
                                              row_pitch(r_[i], r_[j]),
                                              pair_xi_[static_cast<std::size_t>(near[at])]);
    }
    for (int c = 0; c < count; ++c) {
      const auto at = static_cast<std::size_t>(c);
      const Index i = owner_of[at];
      pair_law<Law>(i, static_cast<std::size_t>(near[at]), cand[at], dt, laws,
                    tally_[static_cast<std::size_t>(i)]);
    }
  }
}

// The bond and contact laws of owned pair k = (i, j) (pair_pass).
template <int D>
template <class Law>
inline void DemPart<D>::pair_law(Index i, std::size_t k, const Candidate<Law>& cand, Real dt,
                                 const LawPair<Law>& laws, PairTally& tally) {
  const std::size_t base = static_cast<std::size_t>(i) * kMaxContacts;
  const bool rolling = rolling_.friction > 0;
  const bool bonds = !bond_partner_.empty();
  const bool pair_energy = !cache_.elastic.empty();
  const Vec<D> x_i = x_[i];
  const Real r_i = r_[i];
  const Index j = pair_j_[k];
  std::uint8_t& last_flags = cache_.flags[k];
  const int bond = bonds ? find_bond(i, id_[j]) : -1;
  if (bonds && bond < 0) {
    const Real reach = r_i + r_[j];
    if ((x_i - x_[j]).squaredNorm() > reach * reach * kTouchMargin) {
      if (last_flags) clear_pair(k, last_flags);
      return;
    }
  }
  std::uint8_t flags = 0;
  Real elastic = 0;
  const ContactGeometry<D>& g = cand.g;
  if (!g.touching() && bond < 0) {
    if (last_flags) clear_pair(k, last_flags);
    return;
  }
  const RelativeVelocity<D> rel =
      relative_velocity<D>(g, BodyMotion<D>{v_[i], w_[i]}, BodyMotion<D>{v_[j], w_[j]});
  if (bond >= 0) {
    // Parallel bond (paper eqs. 17-24), in parallel with the contact below.
    const std::size_t at = base + static_cast<std::size_t>(bond);
    const ParallelBondResult<D> br = parallel_bond<D>(bond_law_, g, rel, bond_[at], dt);
    ++tally.bonds_seen;
    if (br.broken) {
      // The energy the bond held is lost with it: the mean of last step's state and the
      // broken one, since the first half-kick of this step still used last step's bond
      // force (velocity Verlet), so the kinetic energy paid half the last increment.
      ++tally.breaks;
      tally.released +=
          Real(0.5) * (parallel_bond_energy<D>(bond_law_, bond_[at]) + br.elastic_energy);
    } else {
      ++tally.bonds;
      flags |= kBondOn;
      cache_.bond_f1[k] = br.force_on_1;
      cache_.bond_t1[k] = br.torque_on_1;
      cache_.bond_t2[k] = br.torque_on_2;
      tally.force += br.force_on_1;
      tally.torque += br.torque_on_1;
      tally.elastic += br.elastic_energy;
      elastic += br.elastic_energy;
      bond_partner_new_[base + static_cast<std::size_t>(tally.bond_slots)] = id_[j];
      bond_new_[base + static_cast<std::size_t>(tally.bond_slots)] = br.state;
      ++tally.bond_slots;
    }
  }
  if (g.touching()) {
    const ContactForce<D> cf =
        rate_contact<Law>(laws.grain, grain_rate_, g, rel, cand.prep, dt, r_i, r_[j]);
    RollingTorque<D> rt;
    if (rolling)
      rt = rolling_resistance<D>(
          rolling_, g, rel,
          RollingLoad{.normal_force = cf.normal_force,
                      .normal_stiffness = cf.normal_stiffness,
                      .inertia_eff = rolling_inertia_eff(RollingBody{inertia_[i], m_[i], r_i},
                                                         RollingBody{inertia_[j], m_[j], r_[j]})},
          pair_roll_[k], dt);
    flags |= kContactOn;
    if (scatter_) {
      Received& into = received_[static_cast<std::size_t>(j)];
      into.force -= cf.force_on_1;
      into.torque += cf.torque_on_2 - rt.torque_on_1;
    } else {
      ContactResult& c = cache_.contact[k];
      c.f1 = cf.force_on_1;
      c.t2 = cf.torque_on_2 - rt.torque_on_1;
    }
    const AngularVec<D> t1 = cf.torque_on_1 + rt.torque_on_1;
    tally.force += cf.force_on_1;
    tally.torque += t1;
    if (outflow_remove_) cache_.t1[k] = t1;
    pair_xi_[k] = cf.shear_history;
    if (rolling) pair_roll_[k] = rt.history;
    count_contact(i, tally);
    const Real stored = cf.elastic_energy + rt.elastic_energy;
    tally.elastic += stored;
    elastic += stored;
    tally.dissipated += cf.dissipated_power + rt.dissipated_power;
  } else if (last_flags & kContactOn) {
    cache_.contact[k] = ContactResult{};
    pair_xi_[k] = Vec<D>::Zero();
    if (rolling) pair_roll_[k] = angular_zero<D>();
  }
  last_flags = flags;
  if (pair_energy) cache_.elastic[k] = elastic;
}

// A pair that was evaluated last step and is apart now: no force, no history.
template <int D>
inline void DemPart<D>::clear_pair(std::size_t k, std::uint8_t& flags) {
  if (flags & kContactOn) {
    cache_.contact[k] = ContactResult{};
    pair_xi_[k] = Vec<D>::Zero();
    if (!pair_roll_.empty()) pair_roll_[k] = angular_zero<D>();
  }
  flags = 0;
}

template <int D>
template <class Law, bool Stress>
inline void DemPart<D>::grain_pass(Index i, Real dt, const LawPair<Law>& laws) {
  SymTensor* moment = nullptr;  // the walls' stress moments (Stress: a frame's stage)
  if constexpr (Stress) {
    moment = &stress_[i];
    *moment = SymTensor::Zero();
  }
  PairTally tally = tally_[static_cast<std::size_t>(i)];
  Vec<D> force;
  AngularVec<D> torque;
  const int bonds = gather_shares(i, tally, force, torque);
  // Whether another grain pushes on this one (its pairs are kept by either grain; both sums are
  // in `force` now, beside gravity): the absorbing faces' tangential dashpot acts on the bed.
  const bool in_bed = force != Vec<D>(m_[i] * gravity_);
  Real elastic = tally.elastic, dissipated = tally.dissipated;
  rigid_wall_contacts<Law>(i, dt, laws, tally,
                           GrainSum{force, torque, elastic, dissipated, moment});
  // Absorbing walls: the held static reaction plus dashpots (absorbing_wall.hpp).
  const auto [absorbed, static_power] = absorbing_wall_loads(i, force, moment, in_bed);
  if (!bond_partner_new_.empty()) close_bond_slots(i, tally);

  Real local_power = 0;
  if (cfg_.local_damping > 0) {
    // Cundall (1987), paper eq. 25: each component of the unbalanced force opposes the
    // motion with alpha times its magnitude.
    const auto fd = local_damping_force<D>(cfg_.local_damping, force, v_[i]);
    const auto td = local_damping_torque<D>(cfg_.local_damping, torque, w_[i]);
    force += fd.load;
    torque += td.load;
    local_power = fd.dissipated_power + td.dissipated_power;
  }
  local_power += absorbed;
  force_[i] = force;
  torque_[i] = torque;
  note_health(i);
  contacts_[i] = tally.slots;
  elastic_[i] = elastic;
  dissipated_[i] = dissipated;
  // The work of the last step (rates times dt) into the grain's books.
  work_contact_[i] += dt * dissipated;
  // Fields of models that are off stay zero, unwritten (compute_forces does not read them).
  if (cfg_.local_damping > 0 || !cfg_.absorbing_walls.empty()) {
    local_power_[i] = local_power;
    static_power_[i] = static_power;
    work_damping_[i] += dt * local_power;
    work_external_[i] += dt * static_power;
  }
  if (!bond_partner_.empty()) {
    bonds_[i] = bonds;
    bond_breaks_[i] = tally.breaks;
    bond_released_[i] = tally.released;
    work_contact_[i] += tally.released;
  }
}

// grain_pass, first: gravity, the shares of the pairs (j, i) that grain i receives, then its
// own pairs' sum (pair_pass's tally), into force and torque; returns the grain's intact bonds.
template <int D>
inline int DemPart<D>::gather_shares(Index i, const PairTally& tally, Vec<D>& force,
                                     AngularVec<D>& torque) {
  force = m_[i] * gravity_;
  torque = angular_zero<D>();
  int bonds = tally.bonds;
  const auto first = static_cast<std::size_t>(recv_begin_[static_cast<std::size_t>(i)]);
  const auto last = static_cast<std::size_t>(recv_begin_[static_cast<std::size_t>(i) + 1]);
  if (scatter_) {
    Received& from = received_[static_cast<std::size_t>(i)];
    force = from.force;
    torque = from.torque;
    from = Received{m_[i] * gravity_, angular_zero<D>()};
  } else if (cache_.bond_f1.empty()) {
    // No bonds: the pairs in contact add their shares. The flags are 1 byte a pair against a
    // result's 6 words, so the listed pairs not in contact (most of them where radii spread)
    // cost no load of their zero result. Skipping those zeros changes no bit: a sum that starts
    // at +0 or a non-zero value never becomes -0.
    for (std::size_t e = first; e < last; ++e) {
      const auto k = static_cast<std::size_t>(recv_pair_[e]);
      if (!(cache_.flags[k] & kContactOn)) continue;
      const ContactResult& c = cache_.contact[k];
      force -= c.f1;
      torque += c.t2;
    }
  } else {
    for (std::size_t e = first; e < last; ++e) {
      const auto k = static_cast<std::size_t>(recv_pair_[e]);
      const std::uint8_t flags = cache_.flags[k];
      if (flags & kBondOn) {
        ++bonds;
        force -= cache_.bond_f1[k];
        torque += cache_.bond_t2[k];
      }
      if (flags & kContactOn) {
        force -= cache_.contact[k].f1;
        torque += cache_.contact[k].t2;
      }
    }
  }
  force += tally.force;
  torque += tally.torque;
  return bonds;
}

// grain_pass: grain i's contacts with the rigid walls (cfg_.walls), their histories kept per
// grain and wall.
template <int D>
template <class Law>
inline void DemPart<D>::rigid_wall_contacts(Index i, Real dt, const LawPair<Law>& laws,
                                            PairTally& tally, GrainSum sum) {
  const bool rolling = rolling_.friction > 0;
  const std::size_t walls = wall_planes_.size();
  // Grains in the interior (further than r_max from every wall) skip the walls.
  bool near_wall = false;
  const Real reach = r_max_ * kTouchMargin;
  for (int d = 0; d < D; ++d)
    near_wall |= !(x_[i][d] - clear_lo_[d] > reach && clear_hi_[d] - x_[i][d] > reach);
  near_wall |= !bodies_.empty();
  std::uint32_t& live = wall_live_[static_cast<std::size_t>(i)];
  if (!near_wall && live)  // a wall contact left behind in one step (never in practice) ends
    for (std::size_t w = 0; w < walls; ++w)
      clear_wall(live, w, static_cast<std::size_t>(i) * walls + w);
  for (std::size_t w = 0; near_wall && w < walls; ++w) {
    const WallPlane& wall = wall_planes_[w];
    const std::size_t at = static_cast<std::size_t>(i) * walls + w;
    // The distance to the plane is |x_axis - plane|: grains clearly apart skip the geometry.
    if (wall.body ? parts::region_distance<D>(*wall.body, x_[i]) > r_[i] * kTouchMargin
                  : std::abs(x_[i][wall.axis] - wall.plane) > r_[i] * kTouchMargin) {
      clear_wall(live, w, at);
      continue;
    }
    ContactGeometry<D> g;
    if (wall.body) {
      g = body_geometry<D>(*wall.body, x_[i], r_[i]);
    } else {
      Vec<D> foot = x_[i];
      foot[wall.axis] = wall.plane;
      g = sphere_wall_geometry<D>(x_[i], r_[i], foot);
    }
    if (!g.touching()) {
      clear_wall(live, w, at);
      continue;
    }
    const RelativeVelocity<D> rel =
        relative_velocity<D>(g, BodyMotion<D>{v_[i], w_[i]}, BodyMotion<D>{wall.velocity});
    typename Law::Params law = laws.wall;
    if (wall.symmetry) law.friction = 0;  // the grain slides along a plane of symmetry
    const PreparedContact<D> prep =
        prepare_contact<D, Law>(law, g, m_[i], row_pitch(r_[i], r_[i]), wall_xi_[at]);
    const ContactForce<D> cf =
        wall.symmetry ? finish_contact<D, Law>(law, g, rel, prep, dt)
                      : rate_contact<Law>(law, wall_rate_, g, rel, prep, dt, r_[i], Real(0));
    RollingTorque<D> rt;
    if (rolling && !wall.symmetry)
      rt = rolling_resistance<D>(rolling_, g, rel,
                                 RollingLoad{.normal_force = cf.normal_force,
                                             .normal_stiffness = cf.normal_stiffness,
                                             .inertia_eff = rolling_inertia_eff_wall(
                                                 RollingBody{inertia_[i], m_[i], r_[i]})},
                                 wall_roll_[at], dt);
    sum.force += cf.force_on_1;
    if (sum.moment) *sum.moment += contact_moment<D>(Vec<D>(-g.arm1 * g.normal), cf.force_on_1);
    sum.torque += cf.torque_on_1 + rt.torque_on_1;
    wall_xi_[at] = cf.shear_history;
    if (rolling) wall_roll_[at] = rt.history;
    if (!moving_.empty()) wall_load_[at] = wall_load(wall, cf, prep);  // measure_walls
    live |= 1u << w;
    count_contact(i, tally);
    sum.elastic += cf.elastic_energy + rt.elastic_energy;
    sum.dissipated += cf.dissipated_power + rt.dissipated_power;
  }
}

// grain_pass: the absorbing walls' forces on grain i (absorbing_wall.hpp); returns the power
// their dashpots absorb and that of the held static reactions [W].
template <int D>
inline std::pair<Real, Real> DemPart<D>::absorbing_wall_loads(Index i, Vec<D>& force,
                                                              SymTensor* moment, bool in_bed) {
  Real absorbed = 0, static_power = 0;
  if (cfg_.absorbing_walls.empty()) return {absorbed, static_power};
  const Real g_norm = gravity_.norm();
  const Real height = g_norm > 0 ? Real(-x_[i].dot(gravity_) / g_norm) : Real(0);
  for (std::size_t k = 0; k < cfg_.absorbing_walls.size(); ++k) {
    // The face's plane and normal into the bed (not the grain's: one whose centre has crossed
    // the face is leaving, remove_outflow, and meets it no more). Above the ground it had at
    // t = 0 the face is open: a grain there passes.
    if (height > absorbing_top_[k]) continue;
    const WallPlane w = wall_plane(cfg_.absorbing_walls[k]);
    const Real gap = w.upper ? w.plane - x_[i][w.axis] : x_[i][w.axis] - w.plane;
    if (!(gap > 0 && gap < r_[i])) continue;
    Vec<D> normal = Vec<D>::Zero();
    normal[w.axis] = w.upper ? -1 : 1;
    const AbsorbingWallForce<D> aw =
        absorbing_wall_force<D>(absorbing_, absorbing_wall_area<D>(r_[i]), normal, v_[i],
                                static_reaction_[i][w.axis], in_bed);
    force += aw.force;
    if (moment) *moment += contact_moment<D>(Vec<D>(-gap * normal), aw.force);
    absorbed += aw.dissipated_power;
    static_power += aw.static_power;
  }
  return {absorbed, static_power};
}

// grain_pass, with bonds: empties grain i's bond slots past this step's (their states too, so
// that a checkpoint holds no state of an older step, whichever rank held the grain then), and
// checks that every bond it owned was met in the list (kBondReach).
template <int D>
inline void DemPart<D>::close_bond_slots(Index i, const PairTally& tally) {
  const std::size_t base = static_cast<std::size_t>(i) * kMaxContacts;
  for (int k = tally.bond_slots; k < kMaxContacts; ++k) {
    bond_partner_new_[base + static_cast<std::size_t>(k)] = kNoContact;
    bond_new_[base + static_cast<std::size_t>(k)] = ParallelBondState<D>{};
  }
  int owned = 0;
  for (int k = 0; k < kMaxContacts; ++k)
    owned += bond_partner_[base + static_cast<std::size_t>(k)] != kNoContact;
  if (tally.bonds_seen != owned) {
#pragma omp critical(crater_dem_overflow)
    bond_lost_ = std::min(bond_lost_, i);
  }
}

// A ghost's bond slots past those its pairs wrote this step (pair_law) emptied, so that a bond
// that broke, or one with a grain of another rank, is not read back from an older step. No
// count of its bonds is checked: its owner checks them.
template <int D>
inline void DemPart<D>::close_ghost_bond_slots(Index i) {
  const std::size_t base = static_cast<std::size_t>(i) * kMaxContacts;
  for (int k = tally_[static_cast<std::size_t>(i)].bond_slots; k < kMaxContacts; ++k) {
    bond_partner_new_[base + static_cast<std::size_t>(k)] = kNoContact;
    bond_new_[base + static_cast<std::size_t>(k)] = ParallelBondState<D>{};
  }
}

// Wall w of a grain with live-contact bits `live` (history slot at): no contact, no history.
template <int D>
inline void DemPart<D>::clear_wall(std::uint32_t& live, std::size_t w, std::size_t at) {
  if (!(live >> w & 1u)) return;
  live &= ~(1u << w);
  wall_xi_[at] = Vec<D>::Zero();
  if (!wall_roll_.empty()) wall_roll_[at] = angular_zero<D>();
}

template void DemPart<2>::compute_forces(Real);
template void DemPart<3>::compute_forces(Real);
template Index DemPart<2>::begin_forces(Real);
template Index DemPart<3>::begin_forces(Real);
template void DemPart<2>::force_block(Index);
template void DemPart<3>::force_block(Index);
template void DemPart<2>::end_forces();
template void DemPart<3>::end_forces();

}  // namespace crater::dem::detail
