// The DEM part's class, internal to src/dem (dem_part.hpp is the public face). Its members are
// defined by concern, each file instantiating its own for D = 2 and 3:
//   dem_part.cpp       construction, the step's stages (advance, finish_step, contact forces
//                      of other parts), the stable step, make_dem_part
//   dem_pair_loop.cpp  the force stage: pair_pass, grain_pass and the contact laws they inline
//                      (with the rigid and absorbing walls' forces on each grain)
//   dem_walls.cpp      the wall planes, the moving walls (speed or servo stress), the absorbing
//                      walls' impedance and static reactions, the wall guard (reflect_at_walls)
//   dem_bonds.cpp      parallel bonds made at t = 0
//   dem_history.cpp    neighbour lists, contact histories packed and unpacked across rebuilds,
//                      the grains' slots permuted with them
//   dem_state.cpp      checkpoints, outflow removal, energies, diagnostics, fault checks
//   dem_stress.cpp     the output fields, the grains' stress of a frame (grain_stresses)
//   dem_settling.cpp   settle_grains, packing_key_text, random_grains
// The contact law comes from the registry (contact_laws.hpp); nothing here names a law.
//
// The DEM pair loop gathers per grain: each grain sums the forces of all its contacts. A
// contact is always evaluated with body 1 = the grain of lower id, so both grains compute the
// same numbers bit for bit and take +F and -F: momentum is conserved exactly, and the result
// does not depend on the number of threads. The grain of lower id owns the contact's history
// (the tangential spring, LAMMPS-style), keyed by the partner's id, so it survives neighbour
// rebuilds and re-sorting; histories are read from last step's buffer and written to a new
// one, so no grain writes what another reads. Parallel bonds are kept the same way: made at
// t = 0 between touching grains, held by the lower id keyed by the partner's id, updated by
// both grains from last step's state (identical numbers), written by the owner only.
//
// The contact law is chosen once per part: the pair loop is a template on the law
// (std::visit over the part's law pair), so no contact branches on it.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "dem/contact_laws.hpp"
#include "dem/dem_part.hpp"
#include "dem/laws/absorbing_wall.hpp"
#include "dem/laws/contact_force.hpp"
#include "dem/laws/contact_geometry.hpp"
#include "dem/laws/grain_stress.hpp"
#include "dem/laws/parallel_bond.hpp"
#include "dem/laws/rate_dependent_friction.hpp"
#include "dem/laws/rolling_resistance.hpp"
#include "dem/packing.hpp"
#include "fields/field_set.hpp"
#include "neighbors/neighbor_list.hpp"
#include "neighbors/verlet_skin.hpp"
#include "parallel/comm.hpp"
#include "parallel/parallel.hpp"
#include "parallel/rcb.hpp"
#include "parts/contact_points.hpp"
#include "parts/outflow.hpp"
#include "parts/part.hpp"
#include "parts/region.hpp"
#include "parts/whole_layout.hpp"

namespace crater::dem::detail {

constexpr Real kSkin = 0.3;  // neighbour-list margin, as a fraction of the largest diameter
constexpr std::int64_t kNoContact = std::numeric_limits<std::int64_t>::min();
// With bonds, the list holds every pair within 2 r_max (1 + kBondReach), so a bond stretched by
// up to 0.1 r_max stays visible; one stretched further is reported as a fault.
constexpr Real kBondReach = 0.05;

// A grain of radius r at x against a fixed body (a box, disk or sphere region): the normal
// points out of the body through the grain's centre (for a centre inside a box, out of its
// nearest face), the overlap is r less the centre's signed distance to the body's surface.
template <int D>
ContactGeometry<D> body_geometry(const parts::RegionConfig& body, const Vec<D>& x, Real r) {
  if (body.type != parts::RegionType::Box) {
    const Vec<D> c = parts::to_vec<D>(body.center_m);
    const Real dist = (x - c).norm();
    // A centre on the body's own (never in practice): pushed out along the first axis.
    const Vec<D> out = dist > 0 ? Vec<D>((x - c) / dist) : Vec<D>(Vec<D>::UnitX());
    return sphere_wall_geometry<D>(x, r, Vec<D>(c + body.radius_m * out));
  }
  if (!parts::region_contains<D>(body, x)) {
    Vec<D> foot;
    for (int d = 0; d < D; ++d)
      foot[d] = std::clamp(x[d], body.min_m[static_cast<std::size_t>(d)],
                           body.max_m[static_cast<std::size_t>(d)]);
    return sphere_wall_geometry<D>(x, r, foot);
  }
  int axis = 0;
  Real depth = std::numeric_limits<Real>::infinity(), side = 1;
  for (int d = 0; d < D; ++d)
    for (const Real s : {Real(-1), Real(1)}) {
      const auto k = static_cast<std::size_t>(d);
      const Real to_face = s > 0 ? body.max_m[k] - x[d] : x[d] - body.min_m[k];
      if (to_face < depth) {
        depth = to_face;
        axis = d;
        side = s;
      }
    }
  ContactGeometry<D> g;
  g.normal = Vec<D>::Zero();
  g.normal[axis] = side;
  g.overlap = r + depth;
  g.radius_eff = r;
  g.arm1 = -depth;
  g.arm2 = 0;
  return g;
}

// 2D grains are disks per metre of depth (masses, forces and energies per metre, as the SPH and
// FE parts they touch), while Hertz-Mindlin is a law between spheres. Applied as it is to the
// disk's mass (hertz_2d = "single_sphere", LAMMPS' and LIGGGHTS' 2D) the contact is about
// 1/(2r) times too soft for grains per metre of depth: a 2D blast drove grains through one
// another. With hertz_2d = "row_of_spheres" a disk stands for a row of spheres of its radius
// along the depth, 1/p of them per metre with pitch p = r_1 + r_2 (a pair) or 2r (against a
// wall): per metre, the force of one sphere contact carrying the mass m* p, divided by p
// (docs/theory.md §3); restitution, friction and the contact's duration are that sphere
// contact's. pitch = 0: the law as it is (3D, the linear spring, single_sphere).
// The law in two halves (Law::prepare, Law::finish), as the pair loop runs it; evaluate_contact
// is the two in one.
template <int D>
struct PreparedContact {
  Real pitch = 0;
  ContactPrep<D> part;
};
template <int D, class Law>
[[gnu::always_inline]] inline PreparedContact<D> prepare_contact(const typename Law::Params& p,
                                                                 const ContactGeometry<D>& g,
                                                                 Real mass_eff, Real pitch,
                                                                 const Vec<D>& shear_history) {
  return {pitch,
          Law::template prepare<D>(p, g, pitch > 0 ? mass_eff * pitch : mass_eff, shear_history)};
}
template <int D, class Law>
[[gnu::always_inline]] inline ContactForce<D> finish_contact(const typename Law::Params& p,
                                                             const ContactGeometry<D>& g,
                                                             const RelativeVelocity<D>& rel,
                                                             const PreparedContact<D>& prep,
                                                             Real dt) {
  ContactForce<D> cf = Law::template finish<D>(p, g, rel, prep.part, dt);
  const Real pitch = prep.pitch;
  if (!(pitch > 0)) return cf;
  cf.force_on_1 /= pitch;
  cf.torque_on_1 /= pitch;
  cf.torque_on_2 /= pitch;
  cf.normal_force /= pitch;
  cf.tangential_force /= pitch;
  cf.normal_stiffness /= pitch;
  cf.elastic_energy /= pitch;
  cf.dissipated_power /= pitch;
  return cf;
}

template <int D, class Law>
[[gnu::always_inline]] inline ContactForce<D> evaluate_contact(
    const typename Law::Params& p, const ContactGeometry<D>& g, const RelativeVelocity<D>& rel,
    Real mass_eff, Real pitch, const Vec<D>& shear_history, Real dt) {
  return finish_contact<D, Law>(p, g, rel,
                                prepare_contact<D, Law>(p, g, mass_eff, pitch, shear_history), dt);
}

template <int D>
bool angular_finite(const AngularVec<D>& w) {
  if constexpr (D == 2)
    return std::isfinite(w);
  else
    return w.allFinite();
}

template <int D>
class DemPart final : public parts::Part<D> {
 public:
  static constexpr int kMaxContacts = D == 2 ? 12 : 24;

  /// The grains are `grains` if given (a packing, docs/theory.md), else those placed by hand,
  /// else one per lattice site. `local_damping` overrides the part's (settling).
  explicit DemPart(const PartSettings& settings, const std::vector<Grain<D>>* grains = nullptr,
                   std::optional<Real> local_damping = std::nullopt);

  const std::string& name() const override { return name_; }
  const char* method() const override { return "dem"; }
  Index count() const override;   // dem_ranks.cpp (on ranks: the grains of every rank)
  Real mass_kg() const override;  // dem_state.cpp
  parts::StableStep stable_step() const override;
  void compute_forces(Real t) override;  // dem_pair_loop.cpp
  // The same in three calls (parts::Part): the lists, then the pairs by blocks, then the grains.
  Index begin_forces(Real t) override;
  void force_block(Index block) override;
  void end_forces() override;
  void expect_frame() override {
    stress_step_ = true;
    frame_step_ = true;
  }
  std::optional<parts::Fault> check() const override;  // dem_state.cpp; on ranks, dem_ranks.cpp
  // check() of this rank's grains alone.
  std::optional<parts::Fault> local_check() const;
  std::optional<parts::ContactPoints<D>> contact_points() const override {
    parts::ContactPoints<D> p;
    p.position = lagged_.view(x_);
    p.velocity = &v_;
    p.mass = &m_;
    p.radius = &r_;
    p.angular_velocity = &w_;
    p.surface_offset = &surface_offset_;
    p.surface_overlap = &surface_overlap_;
    p.id = &id_;
    if (!comm_) {
      // Measured again only when the grains changed (contact_extremes_at_).
      if (contact_extremes_at_ != f_.size()) {
        contact_lightest_kg_ = std::numeric_limits<Real>::infinity();
        contact_largest_m_ = -std::numeric_limits<Real>::infinity();
        for (Index i = 0; i < f_.size(); ++i) {
          contact_lightest_kg_ = std::min(contact_lightest_kg_, m_[i]);
          contact_largest_m_ = std::max(contact_largest_m_, r_[i]);
        }
        contact_extremes_at_ = f_.size();
      }
      p.lightest_kg = contact_lightest_kg_;
      p.largest_radius_m = contact_largest_m_;
    }
    return p;
  }
  void add_contact_forces(const std::vector<Vec<D>>& force,
                          const std::vector<AngularVec<D>>& torque) override;
  void add_touched_contact_forces(const std::vector<Vec<D>>& force,
                                  const std::vector<AngularVec<D>>& torque,
                                  std::span<const Index> touched) override;
  void set_contact_lag(Real lag_s) override {
    lagged_.set(x_, lag_s, [&](Index i) { return v_[i]; });  // v_: v^{n+1/2} until finish_step
  }
  void set_next_contact_forces(const std::vector<Vec<D>>& force,
                               const std::vector<AngularVec<D>>& torque) override {
    if (static_cast<Index>(force.size()) != f_.size() ||
        static_cast<Index>(torque.size()) != f_.size())
      throw std::logic_error("dem: next contact forces for another grain count");
    next_contact_.set(force, torque, [&](const auto& f, const auto& t) { take_contact(f, t); });
  }
  void advance(Real t, Real dt) override;
  void finish_step(Real dt) override;
  parts::Energies energies() const override;
  parts::Geometry<D> geometry() const override {
    parts::Geometry<D> g;
    g.points = &x_;
    return g;
  }
  std::vector<fields::FieldView> point_fields() const override;  // dem_stress.cpp
  std::vector<parts::Diagnostic> diagnostics() const override;
  std::vector<std::string> history_columns() const override;  // dem_walls.cpp
  std::vector<Real> history_values() const override;
  void save_state(parts::StateWriter& w) const override;
  void load_state(parts::StateReader& r) override;

  void add_diagnostic(std::string name, Real value) {
    // Built in place: GCC 12 warns (-Warray-bounds, a false positive) on copying a braced
    // temporary's string here.
    parts::Diagnostic& d = diagnostics_.emplace_back();
    d.name = std::move(name);
    d.value = value;
  }
  /// The grains in id order (positions and radii).
  std::vector<Grain<D>> grains() const;
  /// The grains' contact histories in id order, less the contacts with fixed bodies (those
  /// exist only while settling).
  ContactHistory<D> contact_history() const;
  /// Starts from these histories (grains as placed, in id order): contacts that were live
  /// carry their springs into the first step.
  void start_from(const ContactHistory<D>& h);
  /// Mean kinetic energy per grain, and m g r of the mean grain (the settling scale).
  std::pair<Real, Real> settling_measure() const;
  /// The grains' unbalanced force over their weight, sum |F_i| / sum m_i |g| (1 for grains
  /// falling freely, 0 in static equilibrium; F_i after local damping).
  Real unbalanced_ratio() const;

  /// Spreads the grains over the ranks of `comm` (issue 29, docs/distributed.md, "The DEM part
  /// on ranks"; dem_ranks.cpp), once, before the first step, when every rank has built the whole
  /// part: each rank keeps the grains of its box of a recursive coordinate bisection and, from
  /// the next force stage on, holds copies (ghosts) of the other ranks' grains within reach of
  /// its own. Results are then those of one rank, bit for bit, moving walls included (their loads
  /// are sums over the ranks, measure_walls).
  void distribute(const parallel::Comm& comm) override;
  std::optional<parts::GatheredPoints<D>> gathered_points() const override;
  std::optional<parts::GatheredPoints<D>> own_piece() const override;
  std::optional<parts::OwnNumbers> own_numbers() const override;
  Real load_ratio() const override { return load_ratio_; }
  fields::BusyClock* busy_clock() override { return comm_ ? &busy_ : nullptr; }
  std::vector<parts::Diagnostic> rank_figures() const override;
  const parts::WholeLayout* contact_layout() const override;
  /// The grains in this rank's arrays: its own and, on ranks, the ghosts.
  Index local_count() const { return f_.size(); }
  /// Grain i is a ghost: a copy of a grain another rank owns.
  bool ghost(Index i) const { return !ghost_.empty() && ghost_[at(i)] != 0; }

 private:
  // A rigid face of the domain box as the loops use it, or (body set) a fixed body: the
  // region of a part this one is carved around, held in place while the grains settle.
  struct WallPlane {
    int axis = 0;
    bool upper = false;  // the face at domain_hi_ (else domain_lo_)
    Real plane = 0;      // its coordinate on the axis [m]
    const parts::RegionConfig* body = nullptr;
    Vec<D> velocity = Vec<D>::Zero();  // of a moving wall (cfg_.wall_motion), over the last step
    bool symmetry = false;             // a plane of symmetry: no friction, no rolling resistance
  };
  // A moving wall (a face of cfg_.wall_motion): its slot in wall_planes_ and guard_planes_
  // (that of its face in cfg_.walls) and what the servo carries from step to step.
  struct MovingWall {
    std::size_t slot = 0;
    Real plane = 0;          // its coordinate [m] (checkpoints)
    Real velocity_out = 0;   // along the outward normal, over the last step [m/s]
    Real moved_out = 0;      // the last step's displacement, outward, until its work is booked [m]
    Real force_n = 0;        // normal force on the grains (compression > 0) at the last force
                             // stage [N] (2D: per metre of depth)
    Real elastic_n = 0;      // the part of force_n in the contacts' springs [N]
    Real stiffness_n_m = 0;  // the summed normal stiffness dF_n^el/d(delta) of its contacts
  };
  // A grain's contact with a wall in this force stage (moving walls only): its normal force on
  // the grain along the face's inward normal, and its stiffness.
  struct WallLoad {
    Real force = 0, elastic = 0, stiffness = 0;  // F_n, F_n^el [N], dF_n^el/d(delta) [N/m]
  };
  // A contact's load on a plane wall, as finish_contact scales the forces (per metre with rows
  // of spheres).
  static WallLoad wall_load(const WallPlane& wall, const ContactForce<D>& cf,
                            const PreparedContact<D>& prep) {
    const Real f = cf.force_on_1[wall.axis];
    const Real spring = prep.part.spring.elastic_force;
    return {wall.upper ? -f : f, prep.pitch > 0 ? spring / prep.pitch : spring,
            cf.normal_stiffness};
  }

  // The pair loop runs in two passes, so that each contact is evaluated once, by its body 1
  // (the grain of lower id), with no two threads adding to one grain:
  //   pair_pass (per grain i): its owned pairs (i, j), id_i < id_j, in list order: bond and
  //     contact laws, the pair's history and i's energies; i's share of the forces is summed
  //     on the spot (PairTally), j's share goes to the pair's cache;
  //   grain_pass (per grain i): gravity, then the shares of the pairs (j, i) that i receives,
  //     in pair order (ascending owner, then the owner's list order), then its own sum; then
  //     walls and damping.
  // Every sum runs in an order fixed by the lists alone: the same numbers on any thread count.
  // On one thread (no bonds, no outflow) pair_pass adds j's share to j's running sum at once
  // (Received; it starts at m_j g), in the order the gather would: the pairs are met in
  // ascending order, so the sums, and the results, are those of the gather, bit for bit; the
  // cache is neither written nor read back.
  // Most list entries are not in contact (the list reaches (1 + kSkin) x the contact
  // distance): a squared-distance test with a margin rejects them before any law work.
  // Body 2's share of a contact, what the gather reads at once; zero while the pair is not in
  // contact, so that the gather may add it regardless. Which pairs hold anything: flags.
  struct ContactResult {
    Vec<D> f1 = Vec<D>::Zero();            // force on body 1 (body 2 gets -f1)
    AngularVec<D> t2 = angular_zero<D>();  // torque on body 2
  };
  // A grain's received shares summed as they come (one thread: see above).
  struct Received {
    Vec<D> force = Vec<D>::Zero();  // m g minus the f1 of the pairs (j, i) met so far
    AngularVec<D> torque = angular_zero<D>();
  };
  struct PairCache {
    std::vector<std::uint8_t> flags;  // kBondOn, kContactOn
    std::vector<ContactResult> contact;
    std::vector<Vec<D>> bond_f1;
    std::vector<AngularVec<D>> bond_t1, bond_t2;
    // Kept for outflow only (a grain that leaves takes its partners' share of the energy with
    // it, and the forces it exerted leave its partners): the elastic energy of the pair's
    // contact and bond [J] and the contact's torque on body 1; read only where flags is set.
    std::vector<Real> elastic;
    std::vector<AngularVec<D>> t1;
    void resize(std::size_t n, bool bonds, bool outflow) {
      flags.assign(n, 0);
      contact.assign(n, ContactResult{});
      if (bonds) {
        bond_f1.resize(n);
        bond_t1.resize(n);
        bond_t2.resize(n);
      }
      if (outflow) {
        elastic.assign(n, 0);
        t1.assign(n, angular_zero<D>());
      }
    }
  };
  static constexpr std::uint8_t kBondOn = 1, kContactOn = 2;
  // |d|^2 > (r_1 + r_2)^2 x kTouchMargin: certainly apart (the exact test, overlap =
  // r_1 + r_2 - |d| > 0, follows for the rest; the margin covers the rounding of both sides).
  static constexpr Real kTouchMargin = 1 + 1e-12;

  // What pair_pass leaves for grain_pass, per grain.
  struct PairTally {
    Vec<D> force = Vec<D>::Zero();  // sum of the owned pairs' forces and torques on i
    AngularVec<D> torque = angular_zero<D>();
    Real elastic = 0, dissipated = 0, released = 0;
    int slots = 0, bond_slots = 0, bonds = 0, breaks = 0, bonds_seen = 0;
  };
  // What grain_pass sums for its grain, as its steps add to it: references to grain_pass's
  // own locals (a struct of values passed in and out kept them in memory: 6 % slower).
  struct GrainSum {
    Vec<D>& force;
    AngularVec<D>& torque;
    Real& elastic;
    Real& dissipated;
    SymTensor* moment;  // the walls' stress moments, a frame's stage only (else null)
  };

  // pair_pass runs in chunks of the grain's owned pairs: a branch-free scan first keeps the
  // pairs that may touch (or hold a bond); then the geometry and the law's roots (Law::prepare:
  // the distance, the Hertz spring, the dashpots) for all of those, in short independent
  // iterations that the processor overlaps; then the rest of each law, in list order. One
  // contact is a long chain of roots and divisions: evaluated one after the other, the
  // contacts wait on their chains (measured: 1.2x the contact rate in
  // bench/bench_dem_kernels.cpp batched).
  static constexpr int kScanChunk = 32;
  template <class Law>
  struct Candidate {
    ContactGeometry<D> g;
    PreparedContact<D> prep;
  };

  // pair_pass works on a block [first, last) of kPairBlock consecutive grains, whose owned
  // pairs are contiguous (pair_begin_), so that a chunk of candidates spans several grains.
  static constexpr Index kPairBlock = 16;

  // Construction steps (dem_part.cpp; the walls' in dem_walls.cpp).
  void init_laws(const PartSettings& settings);
  void place_grains(const std::vector<Vec<D>>& pts, const std::vector<Real>& radii,
                    const std::vector<Vec<D>>& vel);
  void init_walls(bool settling);
  // The clear and guard boxes from the current planes (init_walls, move_walls).
  void place_walls();
  // Moving walls (dem_walls.cpp): advance moves them over the step (velocity or servo, from the
  // last force stage's loads), compute_forces sums their loads and books their work.
  void move_walls(Real t, Real dt);
  void measure_walls();
  void set_wall_planes();  // from moving_ (move_walls, load_state)
  // The current area of a face normal to `axis` (2D: its length x 1 m): the extent between the
  // walls of each other axis, or the domain's where there is none.
  Real wall_area(int axis) const;
  void init_absorbing_walls(const PartSettings& settings);
  void make_bonds();  // dem_bonds.cpp

  bool in_domain(Index i) const {
    for (int d = 0; d < D; ++d)
      if (!(x_[i][d] >= domain_lo_[d] && x_[i][d] <= domain_hi_[d])) return false;
    return true;
  }
  // Beyond an absorbing face (its centre has crossed it): the grain leaves the model.
  bool through_absorbing_wall(Index i) const {
    for (const parts::Face face : cfg_.absorbing_walls) {
      const WallPlane w = wall_plane(face);
      if (w.upper ? x_[i][w.axis] > w.plane : x_[i][w.axis] < w.plane) return true;
    }
    return false;
  }
  // Stays in the model at the end of the step (remove_outflow).
  bool stays(Index i) const { return leave_domain_ ? in_domain(i) : !through_absorbing_wall(i); }
  bool healthy(Index i) const {
    return force_[i].allFinite() && angular_finite<D>(torque_[i]) &&
           (leave_domain_ ? x_[i].allFinite() : in_domain(i) || through_absorbing_wall(i));
  }
  // check()'s test of grain i, made where its force is summed (grain_pass, and again when the
  // contacts with other parts add theirs): the first failing grain is kept.
  void note_health(Index i) {
    if (healthy(i)) return;
#pragma omp critical(crater_dem_overflow)
    unhealthy_ = std::min(unhealthy_, i);
  }

  // The key of wall w's contacts in the packed history: -1 - its face, or for the b-th fixed
  // body -1 - (6 + b) (after every face).
  std::int64_t wall_key(std::size_t w) const {
    return w < cfg_.walls.size() ? -1 - static_cast<std::int64_t>(cfg_.walls[w])
                                 : -7 - static_cast<std::int64_t>(w - cfg_.walls.size());
  }
  WallPlane wall_plane(parts::Face face) const {
    WallPlane w;
    w.axis = static_cast<int>(face) / 2;
    w.upper = static_cast<int>(face) % 2 == 1;
    w.plane = w.upper ? domain_hi_[w.axis] : domain_lo_[w.axis];
    w.symmetry = std::find(symmetry_.begin(), symmetry_.end(), face) != symmetry_.end();
    return w;
  }
  // Inside every face (x <= an upper plane, x >= a lower one): reflect_at_walls has nothing
  // to do.
  bool inside_guard(Index i) const {
    bool inside = true;
    for (int d = 0; d < D; ++d)
      inside &= x_[i][d] >= guard_lo_[d] && x_[i][d] <= guard_hi_[d];
    return inside;
  }
  void reflect_at_walls(Index i, Real& count, Real& lost);  // dem_walls.cpp
  void add_bed_measures(const PartSettings& settings);      // dem_part.cpp
  // The sum of term(i) over the grains this rank owns, and over the ranks, plus each rank's
  // `extra`: the bits of one sum of all the terms in any order (parallel::reproducible_sum;
  // collective on ranks). dem_state.cpp.
  template <class Term>
  Real total(Term&& term, Real extra = 0) const;
  void grain_stresses();  // dem_stress.cpp

  // The pitch of evaluate_contact: r_1 + r_2 (a wall: r_1 = r_2 = r) with hertz_2d =
  // "row_of_spheres", else 0 (the law as it is).
  Real row_pitch(Real r1, Real r2) const {
    return rows_ ? r1 + r2 : Real(0);
  }

  // Outflow (dem_state.cpp).
  void remove_outflow();
  std::vector<Real> unhook_leaving();
  void compact_survivors();
  template <class... Payload>
  void compact_slots(std::vector<std::int64_t>& key, std::span<const std::int64_t> gone,
                     std::vector<Payload>&... payload);
  Index pair_owner(std::size_t k) const;
  // The checkpoint blocks after the contact history, for both directions (Self: const for
  // writing), so that save_state and load_state cannot drift apart (dem_state.cpp).
  // `skin`: the part's own, or (a checkpoint written on ranks) the whole bed's.
  // `bond_partner`, `bond`: the part's bonds, or (a checkpoint written on ranks) the whole bed's.
  template <class Archive, class Self, class Skin, class BondPartner, class Bond>
  static void archive_bonds_and_ledgers(Archive& a, Self& s, Skin& skin, BondPartner& bond_partner,
                                        Bond& bond);
  // save_state on ranks: the whole part written by the root rank as one rank would (dem_ranks.cpp).
  void save_gathered(parts::StateWriter& w) const;

  // Ranks (dem_ranks.cpp): at a rebuild, the ghosts go, grains that left this rank's box move
  // to their owner with their packed histories, and the new ghosts arrive with theirs (within
  // `reach` of this rank's grains); at every force stage, the ghosts' motion is refreshed.
  void redistribute(Real reach);
  void distribute_restored();  // distribute() of a part loaded from a checkpoint
  // Grains as the ranks send them: every field, then the packed slots of each (a message of
  // pack_grains is read by unpack_grains into any set of the part's fields and slots).
  struct PackedSlots {
    const std::vector<std::int64_t>& partner;
    const std::vector<Vec<D>>& xi;
    const std::vector<AngularVec<D>>& roll;
    const std::vector<std::int64_t>& bond_partner;  // last step's bonds (empty: none)
    const std::vector<ParallelBondState<D>>& bond;
  };
  // Where unpack_grains appends the slots it reads (the part's own, or a checkpoint's whole set).
  struct SlotsInto {
    std::vector<std::int64_t>& partner;
    std::vector<Vec<D>>& xi;
    std::vector<AngularVec<D>>& roll;
    std::vector<std::int64_t>& bond_partner;
    std::vector<ParallelBondState<D>>& bond;
  };
  void pack_grains(std::span<const Index> which, std::vector<std::byte>& out,
                   const PackedSlots& slots) const;
  void clear_wall_slots();
  void unpack_grains(std::span<const std::byte> in, fields::FieldSet<D>& set,
                     const SlotsInto& into) const;
  void keep_grains(std::span<const std::uint8_t> keep);  // with their packed slots
  void resize_bond_scratch();
  void reorder_halo(std::span<const Index> order);
  void refresh_ghosts();

  // Neighbour lists and contact histories (dem_history.cpp).
  void update_neighbors();
  void build_lists();
  void pack_history(std::vector<std::int64_t>& partner, std::vector<Vec<D>>& xi,
                    std::vector<AngularVec<D>>& roll) const;
  void unpack_history();
  int find_slot(Index owner, std::int64_t partner) const;
  void permute_slots(std::span<const Index> order);

  // The force stage (dem_pair_loop.cpp): declared inline, as the loop's steps are inlined into
  // it there.
  inline int find_bond(Index owner, std::int64_t partner) const;
  template <class Law>
  [[gnu::always_inline]] inline ContactForce<D> rate_contact(typename Law::Params p,
                                                             const RateDependentFriction& rate,
                                                             const ContactGeometry<D>& g,
                                                             const RelativeVelocity<D>& rel,
                                                             const PreparedContact<D>& prep,
                                                             Real dt, Real r1, Real r2) const;
  inline void count_contact(Index i, PairTally& tally);
  template <class Law>
  inline void pair_pass(Index first, Index last, Real dt, const LawPair<Law>& laws);
  template <class Law>
  [[gnu::always_inline]] inline void pair_law(Index i, std::size_t k, const Candidate<Law>& cand,
                                              Real dt, const LawPair<Law>& laws, PairTally& tally);
  inline void clear_pair(std::size_t k, std::uint8_t& flags);
  template <class Law, bool Stress>
  inline void grain_pass(Index i, Real dt, const LawPair<Law>& laws);
  [[gnu::always_inline]] inline int gather_shares(Index i, const PairTally& tally, Vec<D>& force,
                                                  AngularVec<D>& torque);
  template <class Law>
  [[gnu::always_inline]] inline void rigid_wall_contacts(Index i, Real dt, const LawPair<Law>& laws,
                                                         PairTally& tally, GrainSum sum);
  [[gnu::always_inline]] inline std::pair<Real, Real> absorbing_wall_loads(Index i, Vec<D>& force,
                                                                           SymTensor* moment,
                                                                           bool in_bed);
  [[gnu::always_inline]] inline void close_bond_slots(Index i, const PairTally& tally);
  inline void close_ghost_bond_slots(Index i);
  inline void clear_wall(std::uint32_t& live, std::size_t w, std::size_t at);

  std::string name_;
  SourceLocation where_;  // of the part in the scenario (errors)
  Settings cfg_;
  Vec<D> gravity_, domain_lo_, domain_hi_;
  bool leave_domain_ = false;    // domain.outflow = "remove": grains outside it are removed
  bool outflow_remove_ = false;  // grains may be removed (leave_domain_ or absorbing walls)
  // Grains that leave are removed in batches (each removal rebuilds the neighbour lists; with
  // transmitting faces a grain leaves almost every step of a blast): outflow_batch_steps_ steps
  // after the first of a batch left (domain.outflow_batch_steps), or at a frame step.
  // outflow_wait_: steps the current batch has waited; frame_step_: expect_frame() was called.
  Index outflow_batch_steps_ = 1;
  Index outflow_wait_ = 0;
  bool frame_step_ = false;
  Real rho_ = 0;
  GranularMaterial grain_;
  ContactLaws laws_;
  RollingResistanceParams rolling_;
  RateDependentFriction grain_rate_, wall_rate_;
  std::vector<parts::Face> symmetry_;  // the domain's planes of symmetry (walls of cfg_.walls)
  ParallelBondParams bond_law_;
  Real r_min_ = 0, r_max_ = 0;

  fields::FieldSet<D> f_;
  std::vector<std::int64_t>& id_;
  std::vector<Vec<D>>& x_;
  std::vector<Vec<D>>& v_;
  std::vector<AngularVec<D>>& w_;
  std::vector<Real>& r_;
  std::vector<Real>& m_;
  std::vector<Real>& inertia_;
  std::vector<Vec<D>>& force_;
  std::vector<AngularVec<D>>& torque_;
  std::vector<Real>& contacts_;
  std::vector<Real>& elastic_;
  std::vector<Real>& dissipated_;
  std::vector<Real>& local_power_;
  std::vector<Real>& bonds_;          // intact bonds of the grain (output when bonds are on)
  std::vector<Real>& bond_breaks_;    // bonds the grain owned that broke this step
  std::vector<Real>& bond_released_;  // energy those bonds held [J]
  // Absorbing walls: per grain, the static reaction F_0 of the face on each axis (a grain
  // touches at most one face of an axis) and the work rate of those reactions.
  std::vector<Vec<D>>& static_reaction_;
  std::vector<Real>& static_power_;
  std::vector<Vec<D>>& contact_force_;  // from contacts with other parts (in force_ too)
  std::vector<AngularVec<D>>& contact_torque_;
  std::vector<Real>& surface_offset_;         // parts::ContactPoints::surface_offset
  std::vector<Real>& surface_overlap_;        // parts::ContactPoints::surface_overlap
  parts::ContactWork contact_;                // work of those forces on the grains
  parts::LaggedPositions<D> lagged_;          // positions the contacts see (multi-rate stepping)
  parts::NextContactForces<D> next_contact_;  // for the next step's first half kick
  // The grains whose contact force or torque may be nonzero (ascending), while held_known_ and
  // the grains have not moved in their arrays since (held_epoch_, f_'s layout epoch): those
  // the last add_touched_contact_forces() was told of. visit_: its scratch.
  std::vector<Index> held_, visit_;
  std::uint64_t held_epoch_ = 0;
  bool held_known_ = false;
  void expect_grain_count(const std::vector<Vec<D>>& force,
                          const std::vector<AngularVec<D>>& torque) const {
    if (static_cast<Index>(force.size()) != f_.size() ||
        static_cast<Index>(torque.size()) != f_.size())
      throw std::logic_error("dem: contact forces for another grain count");
  }
  // One grain's share of the contact forces' hand-over (add_contact_forces): the power of the
  // old and new forces, the new forces in, the grain's health.
  void take_contact_force(Index i, const Vec<D>& force, const AngularVec<D>& torque, bool booking,
                          Real half_dt, std::vector<Real>& power) {
    if (booking)
      power[at(i)] = !ghost(i) ? half_dt * (v_[i].dot(contact_force_[i] + force) +
                                            angular_dot<D>(w_[i], contact_torque_[i] + torque))
                               : Real(0);
    contact_force_[i] = force;
    contact_torque_[i] = torque;
    force_[i] += force;
    torque_[i] += torque;
    note_health(i);
  }
  /// Multi-rate: the next step starts with other contact forces than the last one ended with.
  void take_contact(const std::vector<Vec<D>>& force, const std::vector<AngularVec<D>>& torque) {
    held_known_ = false;
    parallel::for_each(f_.size(), [&](Index i) {
      force_[i] += force[at(i)] - contact_force_[i];
      torque_[i] += torque[at(i)] - contact_torque_[i];
      contact_force_[i] = force[at(i)];
      contact_torque_[i] = torque[at(i)];
    });
  }
  Real wall_reflections_ = 0;  // grains put back from beyond a wall (reflect_at_walls)
  AbsorbingWallParams absorbing_;
  // Per absorbing face (cfg_.absorbing_walls' order): the height (along -gravity) of the
  // highest grain centre touching it at t = 0. Above it the face is open air, not ground: it
  // puts no force on a grain there (init_absorbing_walls, absorbing_wall_loads).
  std::vector<Real> absorbing_top_;
  // The grains' Love-Weber stress (laws/grain_stress.hpp), of frames only: computed in a force
  // stage that expect_frame() announced (stress_step_; the rigid and absorbing walls' moments
  // are summed in its own instance of grain_pass (Stress), the pairs' by
  // grain_stresses), and written while it is of the last force stage (stress_current_). Solid
  // fraction of its V_i: 1 when the part's has none.
  static constexpr const char* kStressField = "stress_pa";
  std::vector<SymTensor>& stress_;
  // The work books, per grain (fields, so that they move with it to another rank): summed over
  // the grains, and the ranks, only when the energies are asked for, by the reproducible sum
  // (total), which gives the same bits whichever rank holds which grain. The part's scalars
  // (external_work_, contact_dissipated_, local_dissipated_, wall_reflections_) keep what is
  // not a grain's: the books of grains removed, the work of moving walls.
  std::vector<Real>& work_external_;  // done on it by gravity and the absorbing walls' static
                                      // reactions [J]
  std::vector<Real>& work_contact_;   // dissipated in the contacts it keeps (its pairs as body
                                      // 1, its walls'), in its bonds that broke (the energy they
                                      // held) and at its reflections off a wall [J]
  std::vector<Real>& work_damping_;   // taken out by local damping and absorbing walls [J]
  std::vector<Real>& reflections_;    // times it was put back from beyond a wall
  bool stress_step_ = false, stress_current_ = false;
  Real solid_fraction_ = 1;

  // Contact history packed at rebuilds: kMaxContacts slots per grain (partner id, tangential
  // spring, rolling moment; pack_history), authoritative while packed_.
  std::vector<std::int64_t> partner_;
  std::vector<Vec<D>> xi_;
  std::vector<AngularVec<D>> roll_;  // rolling moments (empty when mu_r = 0)
  // The slots' storage before the last re-sort (permute_slots), kept for its capacity.
  std::vector<std::int64_t> scratch_ids_;
  std::vector<Vec<D>> scratch_xi_;
  std::vector<AngularVec<D>> scratch_roll_;
  bool packed_ = true;
  // ... and while the list stands: per owned pair and per grain and wall (cfg_.walls order).
  std::vector<Vec<D>> pair_xi_, wall_xi_;
  std::vector<AngularVec<D>> pair_roll_, wall_roll_;  // empty when mu_r = 0
  std::vector<std::uint32_t> wall_live_;  // per grain: bit w, a live contact with wall w
  // The faces of cfg_.walls; with cfg_.absorbing_walls (reflect_at_walls); the box beyond whose
  // planes (r_max away) a grain touches no face of cfg_.walls (+-inf where there is none).
  std::vector<WallPlane> wall_planes_, guard_planes_;  // wall_planes_: the bodies_ last
  std::vector<parts::RegionConfig> bodies_;            // fixed bodies (settling only)
  std::vector<MovingWall> moving_;                     // empty while settling
  std::vector<WallLoad> wall_load_;  // per grain and wall (as wall_xi_), with moving walls
  Vec<D> clear_lo_, clear_hi_;
  Vec<D> guard_lo_, guard_hi_;  // inside these bounds a grain is beyond no face (reflect_at_walls)
  // Bonds: kMaxContacts slots per grain (partner id of higher id, state); empty without bonds
  // (and on a rank that holds none of the part's grains: bonded_ says whether the part has them).
  bool bonded_ = false;
  std::vector<std::int64_t> bond_partner_, bond_partner_new_;
  std::vector<ParallelBondState<D>> bond_, bond_new_;

  neighbors::NeighborList list_;
  // Owned pairs (i, j), id_i < id_j: grain i's at pair_begin_[i] .. pair_begin_[i + 1], j in
  // pair_j_; per list entry, its pair: 2 p if the row's grain owns it, else 2 p + 1.
  std::vector<Index> pair_begin_, pair_j_;     // owned pairs (i, j) of grain i, in list order
  std::vector<Index> recv_begin_, recv_pair_;  // pairs (j, i) that grain i receives, likewise
  PairCache cache_;                            // per owned pair: the contact's results (pair_pass)
  bool scatter_ = false;                       // one thread: received shares summed in pair_pass
  bool scatter_kept_ = false;                  // scatter_ while a frame's force stage sets it aside
  std::vector<Received> received_;             // per grain, with scatter_
  // The largest squared displacement since the list's build, measured by advance; -1: unknown.
  Real moved_sq_ = -1;
  std::vector<PairTally> tally_;
  neighbors::VerletSkin<D> skin_{kSkin};
  // 2D, a law whose disks stand for rows of spheres (row_of_spheres: hertz_2d =
  // "row_of_spheres"; evaluate_contact).
  bool rows_ = false;
  Index overflow_ = 0, bond_lost_ = 0;
  Index unhealthy_ = 0;  // the first grain check() fails (note_health), else the count
  Index bonds_initial_ = 0;
  Real bonds_broken_ = 0;
  Real external_work_ = 0, contact_dissipated_ = 0, local_dissipated_ = 0;
  std::vector<parts::Diagnostic> diagnostics_;
  // Grains removed beyond the domain box (outflow = "remove"): the survivors' mask of the
  // current removal, and how many left, their mass and the energy booked with them (eroded_j).
  parts::OutflowRemoval outflow_;
  Real time_s_ = 0;  // of the last force stage, for the log

  // Ranks (distribute): the communicator (null: one rank, no ghosts), the cuts that give each
  // position its owner, per local grain whether it is a ghost (empty: none), and per rank the
  // local grains whose motion goes there (halo_send_) and the ghosts that come from it
  // (halo_recv_), each in the order of the exchange.
  const parallel::Comm* comm_ = nullptr;
  mutable parts::WholeLayout contact_layout_;  // contact_layout()'s, on ranks
  mutable Index contact_layout_builds_ = -1;   // skin_.builds() it was made at (-1: none)
  // On one rank, the grains' lightest mass and largest radius for contact_points(), measured
  // at this grain count (-1: none since the grains last changed: load_state, remove_outflow).
  mutable Index contact_extremes_at_ = -1;
  mutable Real contact_lightest_kg_ = 0, contact_largest_m_ = 0;
  // On one rank, stable_step()'s limit as measured at this grain count (-1: none since the
  // grains last changed, as above).
  mutable Index step_at_ = -1;
  mutable parts::StableStep step_;
  Index rebalances_ = 0;    // on ranks: how often the cuts were made again
  Real load_ratio_ = 1;     // on ranks: heaviest rank over the mean (last rebuild)
  Index arrivals_ = 0;      // on ranks: grains received from another owner
  fields::BusyClock busy_;  // on ranks: the measured load since the cuts (domain.balance)
  parallel::RcbTree<D> cuts_;
  std::vector<std::uint8_t> ghost_;
  std::vector<std::vector<Index>> halo_send_, halo_recv_;
};

}  // namespace crater::dem::detail
