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
#include "dem/dem_part.hpp"

#include <Eigen/Geometry>  // cross products of 3D contact laws

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <type_traits>
#include <variant>

#include "dem/laws/absorbing_wall.hpp"
#include "dem/laws/contact_geometry.hpp"
#include "dem/laws/hertz_mindlin.hpp"
#include "dem/laws/linear_spring.hpp"
#include "dem/laws/local_damping.hpp"
#include "dem/laws/parallel_bond.hpp"
#include "dem/laws/rate_dependent_friction.hpp"
#include "dem/laws/rolling_resistance.hpp"
#include "dem/packing.hpp"
#include "fields/field_set.hpp"
#include "neighbors/cell_grid.hpp"
#include "neighbors/neighbor_list.hpp"
#include "neighbors/verlet_skin.hpp"
#include "parallel/parallel.hpp"
#include "parts/region.hpp"

namespace crater::dem {
namespace {

using fields::kHalo;
using fields::kNone;
using fields::kOutput;
using fields::kRestart;
using fields::kStateRoles;

constexpr Real kSkin = 0.3;  // neighbour-list margin, as a fraction of the largest diameter
constexpr std::int64_t kNoContact = std::numeric_limits<std::int64_t>::min();
// With bonds, the list holds every pair within 2 r_max (1 + kBondReach), so a bond stretched by
// up to 0.1 r_max stays visible; one stretched further is reported as a fault.
constexpr Real kBondReach = 0.05;

/// The grain-grain and grain-wall parameters of one contact law.
template <class Law>
struct LawPair {
  using Type = Law;
  typename Law::Params grain, wall;
};
using ContactLaws = std::variant<LawPair<HertzMindlin>, LawPair<LinearSpring>>;

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

BondRadiusRule bond_rule(BondRadius r) {
  switch (r) {
    case BondRadius::Mean:
      return BondRadiusRule::MeanRadius;
    case BondRadius::Effective:
      return BondRadiusRule::EffectiveRadius;
    case BondRadius::Min:
      break;
  }
  return BondRadiusRule::MinRadius;
}

using parts::to_vec;

template <int D>
std::vector<AngularVec<D>>& add_angular(fields::FieldSet<D>& f, const char* name, const char* unit,
                                        unsigned roles) {
  if constexpr (D == 2)
    return f.add_scalar(name, unit, roles);
  else
    return f.add_vector(name, unit, roles);
}

template <int D>
Real angular_kinetic(Real inertia, const AngularVec<D>& w) {
  if constexpr (D == 2)
    return 0.5 * inertia * w * w;
  else
    return 0.5 * inertia * w.squaredNorm();
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
                   std::optional<Real> local_damping = std::nullopt)
      : name_(settings.part.name),
        cfg_(settings.dem),
        gravity_(to_vec<D>(settings.part.domain.gravity_m_s2)),
        domain_lo_(to_vec<D>(settings.part.domain.min_m)),
        domain_hi_(to_vec<D>(settings.part.domain.max_m)),
        // A settling part keeps every grain: one that leaves fails the settling.
        outflow_remove_(settings.part.domain.outflow == parts::Outflow::Remove && !local_damping),
        id_(f_.add_integer("id", "1", kStateRoles)),
        x_(f_.add_vector("position", "m", kRestart | kHalo)),
        v_(f_.add_vector("velocity", "m/s", kStateRoles)),
        w_(add_angular<D>(f_, "angular_velocity", "rad/s", kStateRoles)),
        r_(f_.add_scalar("radius", "m", kStateRoles)),
        m_(f_.add_scalar("mass", "kg", kStateRoles)),
        inertia_(f_.add_scalar("moment_of_inertia", "kg m^2", kRestart | kHalo)),
        force_(f_.add_vector("force", "N", kOutput | kRestart)),
        torque_(add_angular<D>(f_, "torque", "N m", kRestart)),
        contacts_(f_.add_scalar("contacts", "1", kOutput)),
        elastic_(f_.add_scalar("contact_energy", "J", kNone)),
        dissipated_(f_.add_scalar("contact_dissipation_rate", "W", kNone)),
        local_power_(f_.add_scalar("local_damping_rate", "W", kNone)),
        bonds_(f_.add_scalar("bonds", "1", settings.dem.bonds.enabled ? kOutput : kNone)),
        bond_breaks_(f_.add_scalar("bond_breaks", "1", kNone)),
        bond_released_(f_.add_scalar("bond_released_energy", "J", kNone)),
        static_reaction_(f_.add_vector("absorbing_wall_reaction", "N", kRestart)),
        static_power_(f_.add_scalar("absorbing_wall_static_power", "W", kNone)),
        contact_force_(f_.add_vector("coupling_force", "N", kRestart)),
        contact_torque_(add_angular<D>(f_, "coupling_torque", "N m", kRestart)),
        surface_offset_(f_.add_scalar("coupling_surface_offset", "m", kRestart)),
        surface_overlap_(f_.add_scalar("coupling_surface_overlap", "m", kRestart)) {
    const parts::PartSetup& pc = settings.part;
    const GranularMaterial& mat = settings.grain;
    rho_ = settings.rho0_kg_m3;
    const ElasticMaterial grain{youngs_modulus_from_shear(mat.shear_modulus_pa, mat.poisson_ratio),
                                mat.poisson_ratio};
    shear_modulus_ = mat.shear_modulus_pa;
    poisson_ = mat.poisson_ratio;
    if (cfg_.contact == ContactLawKind::LinearSpring) {
      // Walls take the grain's springs (k_n, k_s) with their own friction and restitution.
      laws_ = LawPair<LinearSpring>{
          linear_spring_params(cfg_.normal_stiffness_n_m, cfg_.shear_stiffness_n_m, mat.restitution,
                               mat.friction),
          linear_spring_params(cfg_.normal_stiffness_n_m, cfg_.shear_stiffness_n_m,
                               cfg_.wall_restitution, cfg_.wall_friction)};
    } else {
      // Rigid walls of the grain's own elastic constants (as LIGGGHTS' walls of the same
      // material): E* halves the grain-grain one, for a wall radius of infinity.
      laws_ = LawPair<HertzMindlin>{
          hertz_mindlin_params(grain, grain, mat.restitution, mat.friction),
          hertz_mindlin_params(grain, grain, cfg_.wall_restitution, cfg_.wall_friction)};
    }
    rolling_ = RollingResistanceParams{.friction = cfg_.rolling_friction,
                                       .damping_ratio = cfg_.rolling_damping};
    grain_rate_ = rate_dependent_friction(mat.friction, cfg_.friction_rate_beta,
                                          cfg_.friction_reference_strain_rate);
    wall_rate_ = rate_dependent_friction(cfg_.wall_friction, cfg_.friction_rate_beta,
                                         cfg_.friction_reference_strain_rate);
    bond_law_ = ParallelBondParams{.normal_stiffness_pa_m = cfg_.bonds.normal_stiffness_pa_m,
                                   .shear_stiffness_pa_m = cfg_.bonds.shear_stiffness_pa_m,
                                   .tensile_strength_pa = cfg_.bonds.tensile_strength_pa,
                                   .shear_strength_pa = cfg_.bonds.shear_strength_pa};

    std::vector<Vec<D>> pts;
    std::vector<Real> radii;
    std::vector<Vec<D>> vel;
    if (local_damping) {
      cfg_.local_damping = *local_damping;
      // While settling, absorbing faces are rigid walls: the bed settles on them, and the
      // run then holds the reactions they end with (absorbing_wall.hpp).
      cfg_.walls.insert(cfg_.walls.end(), cfg_.absorbing_walls.begin(), cfg_.absorbing_walls.end());
      cfg_.absorbing_walls.clear();
    }
    if (grains) {
      for (const auto& q : *grains) {
        pts.push_back(q.x);
        radii.push_back(q.r);
        vel.push_back(to_vec<D>(pc.initial.velocity_m_s));
      }
    } else if (!cfg_.particles.empty()) {
      for (const auto& q : cfg_.particles) {
        pts.push_back(to_vec<D>(q.center_m));
        radii.push_back(q.radius_m);
        vel.push_back(to_vec<D>(q.velocity_m_s));
      }
    } else {
      pts = parts::region_lattice<D>(pc.region, pc.spacing_m);
      std::mt19937_64 rng(cfg_.seed);
      std::uniform_real_distribution<Real> draw(cfg_.radius_min_m, cfg_.radius_max_m);
      for (std::size_t k = 0; k < pts.size(); ++k) {
        radii.push_back(cfg_.radius_min_m == cfg_.radius_max_m ? cfg_.radius_max_m : draw(rng));
        vel.push_back(to_vec<D>(pc.initial.velocity_m_s));
      }
    }
    if (!pc.carving.empty()) {
      // Leave the carved parts' regions empty (a charge, a plate inside the soil box).
      const std::vector<parts::RegionConfig>& carving = pc.carving;
      std::size_t kept = 0;
      for (std::size_t k = 0; k < pts.size(); ++k) {
        if (parts::carved<D>(carving, pts[k], radii[k])) continue;
        pts[kept] = pts[k];
        radii[kept] = radii[k];
        vel[kept] = vel[k];
        ++kept;
      }
      pts.resize(kept);
      radii.resize(kept);
      vel.resize(kept);
    }
    if (settings.packing.agitation_m_s > 0 && !local_damping) {  // not while settling
      // Random agitation, uniform in +-a per component, drawn in grain order (seeded).
      std::mt19937_64 jitter(settings.dem.seed ^ 0x5deece66dULL);
      std::uniform_real_distribution<Real> draw(-settings.packing.agitation_m_s,
                                                settings.packing.agitation_m_s);
      for (auto& v : vel)
        for (int d = 0; d < D; ++d)
          v[d] += draw(jitter);
    }
    if (pts.empty())
      throw InputError(pc.where, fmt::format("parts[{}].region", pc.name),
                       "the part holds no grains: its region, less what `carve` removes, has "
                       "no lattice point or room for a grain");
    rows_ = D == 2 && cfg_.contact == ContactLawKind::HertzMindlin && cfg_.hertz_row_of_spheres;
    const Index n = static_cast<Index>(pts.size());
    f_.resize(n);
    std::fill(surface_offset_.begin(), surface_offset_.end(), Real(-1));  // not touching
    r_min_ = std::numeric_limits<Real>::infinity();
    for (Index i = 0; i < n; ++i) {
      const Real r = radii[static_cast<std::size_t>(i)];
      id_[i] = i;
      x_[i] = pts[static_cast<std::size_t>(i)];
      v_[i] = vel[static_cast<std::size_t>(i)];
      r_[i] = r;
      // 2D: disks per metre of depth, I = m r^2 / 2; 3D: spheres, I = 2 m r^2 / 5.
      m_[i] = D == 2 ? rho_ * std::numbers::pi * r * r
                     : rho_ * 4.0 / 3.0 * std::numbers::pi * r * r * r;
      inertia_[i] = (D == 2 ? 0.5 : 0.4) * m_[i] * r * r;
      r_min_ = std::min(r_min_, r);
      r_max_ = std::max(r_max_, r);
    }
    partner_.assign(static_cast<std::size_t>(n) * kMaxContacts, kNoContact);
    xi_.assign(static_cast<std::size_t>(n) * kMaxContacts, Vec<D>::Zero());
    if (rolling_.friction > 0)
      roll_.assign(static_cast<std::size_t>(n) * kMaxContacts, angular_zero<D>());
    for (const parts::Face face : cfg_.walls)
      wall_planes_.push_back(wall_plane(face));
    guard_planes_ = wall_planes_;
    for (const parts::Face face : cfg_.absorbing_walls)
      guard_planes_.push_back(wall_plane(face));
    clear_lo_ = Vec<D>::Constant(-std::numeric_limits<Real>::infinity());
    clear_hi_ = Vec<D>::Constant(std::numeric_limits<Real>::infinity());
    for (const WallPlane& w : wall_planes_)
      (w.upper ? clear_hi_ : clear_lo_)[w.axis] = w.plane;
    guard_lo_ = clear_lo_;
    guard_hi_ = clear_hi_;
    for (const WallPlane& w : guard_planes_)
      if (w.upper)
        guard_hi_[w.axis] = std::min(guard_hi_[w.axis], w.plane);
      else
        guard_lo_[w.axis] = std::max(guard_lo_[w.axis], w.plane);
    const std::size_t wall_slots = static_cast<std::size_t>(n) * cfg_.walls.size();
    wall_xi_.assign(wall_slots, Vec<D>::Zero());
    if (cfg_.walls.size() > 32) throw std::logic_error("dem: more than 32 walls");
    wall_live_.assign(static_cast<std::size_t>(n), 0);
    if (rolling_.friction > 0) wall_roll_.assign(wall_slots, angular_zero<D>());
    // A settling part (local damping overridden) carries no bonds: they are made at t = 0 of
    // the run, between the settled grains.
    if (cfg_.bonds.enabled && !local_damping) make_bonds();
    if (!cfg_.absorbing_walls.empty()) init_absorbing_walls(settings);
  }

  const std::string& name() const override { return name_; }
  const char* method() const override { return "dem"; }
  Index count() const override { return f_.size(); }
  Real mass_kg() const override {
    return parallel::deterministic_sum<Real>(f_.size(), [&](Index i) { return m_[i]; });
  }

  parts::StableStep stable_step() const override {
    parts::StableStep s;
    for (Index i = 0; i < f_.size(); ++i)
      if (r_[i] == r_min_) {
        s.entity_id = id_[i];
        break;
      }
    s.dt_s = std::numeric_limits<Real>::infinity();
    if (cfg_.contact == ContactLawKind::HertzMindlin) {
      // Rayleigh step of the smallest grain (Li, Xu & Thornton 2005): the time a Rayleigh
      // wave takes across it; DEM codes run at 10-30 % of it.
      s.dt_s = cfg_.rayleigh_fraction * rayleigh_time_step(r_min_, rho_, shear_modulus_, poisson_);
      s.reason = fmt::format("{} x Rayleigh step of the smallest grain (r = {:.4g} m)",
                             cfg_.rayleigh_fraction, r_min_);
    }
    // Linear springs and bonds: f sqrt(m_min / k_max) (O'Sullivan & Bray 2004: 0.17 covers the
    // rotational modes and several contacts per grain; 2 sqrt(m/k) is the bare oscillator's
    // limit). Bonds act in parallel with the contact, so their stiffness adds.
    Real k = 0;
    if (cfg_.contact == ContactLawKind::LinearSpring)
      k += std::max(cfg_.normal_stiffness_n_m, cfg_.shear_stiffness_n_m);
    if (cfg_.bonds.enabled)
      k += std::max(bond_law_.normal_stiffness_pa_m, bond_law_.shear_stiffness_pa_m) *
           bond_section<D>(cfg_.bonds.radius_multiplier * r_max_).area;
    if (k > 0) {
      const Real m_min = D == 2 ? rho_ * std::numbers::pi * r_min_ * r_min_
                                : rho_ * 4.0 / 3.0 * std::numbers::pi * r_min_ * r_min_ * r_min_;
      const Real dt = cfg_.stiffness_step_fraction * std::sqrt(m_min / k);
      if (dt < s.dt_s) {
        s.dt_s = dt;
        s.reason = fmt::format(
            "{} x sqrt(m/k) of the smallest grain (m = {:.4g} kg, k = {:.4g} "
            "N/m{})",
            cfg_.stiffness_step_fraction, m_min, k, cfg_.bonds.enabled ? ", contact + bond" : "");
      }
    }
    if (absorbing_.normal_impedance > 0) {
      // An explicit dashpot on a grain is stable below 2 m / \eta; keep half of that.
      const Real m_min = D == 2 ? rho_ * std::numbers::pi * r_min_ * r_min_
                                : rho_ * 4.0 / 3.0 * std::numbers::pi * r_min_ * r_min_ * r_min_;
      const Real eta = std::max(absorbing_.normal_impedance, absorbing_.tangential_impedance) *
                       absorbing_wall_area<D>(r_min_);
      if (m_min / eta < s.dt_s) {
        s.dt_s = m_min / eta;
        s.reason = fmt::format(
            "m / eta of the smallest grain on an absorbing wall (eta = {:.4g} "
            "N s/m)",
            eta);
      }
    }
    return s;
  }

  void compute_forces(Real t) override {
    time_s_ = t;
    update_neighbors();
    const Index n = f_.size();
    const Real dt = last_dt_;
    overflow_ = n;
    bond_lost_ = n;
    unhealthy_ = n;
    std::visit(
        [&](const auto& laws) {
          using Law = typename std::decay_t<decltype(laws)>::Type;
          parallel::for_each_block(n, kPairBlock, [&](Index first, Index last) {
            pair_pass<Law>(first, last, dt, laws);
          });
          parallel::for_each(n, [&](Index i) { grain_pass<Law>(i, dt, laws); });
        },
        laws_);
    // Bonds of this step become last step's (contact histories are updated in place).
    bond_partner_.swap(bond_partner_new_);
    bond_.swap(bond_new_);
    // Energy taken out over the last step by contacts and local damping (rates times dt), and
    // the energy the bonds that broke held.
    struct Sums {
      Real dissipated = 0, local = 0, released = 0, breaks = 0, wall_work = 0;
      Sums& operator+=(const Sums& o) {
        dissipated += o.dissipated;
        local += o.local;
        released += o.released;
        breaks += o.breaks;
        wall_work += o.wall_work;
        return *this;
      }
    };
    const bool bonded = !bond_partner_.empty();
    const bool damped = cfg_.local_damping > 0 || !cfg_.absorbing_walls.empty();
    const Sums s = parallel::deterministic_sum<Sums>(n, [&](Index i) {
      // The models that are off leave their fields at zero (grain_pass): not read.
      if (!bonded && !damped) return Sums{dissipated_[i]};
      return Sums{dissipated_[i], local_power_[i], bond_released_[i], bond_breaks_[i],
                  static_power_[i]};
    });
    contact_dissipated_ += dt * s.dissipated + s.released;
    local_dissipated_ += dt * s.local;
    external_work_ += dt * s.wall_work;
    bonds_broken_ += s.breaks;
  }

  std::optional<parts::Fault> check() const override {
    const Index n = f_.size();
    if (overflow_ < n)
      return parts::Fault{id_[overflow_],
                          fmt::format("more than {} contacts on one grain: grains overlap far "
                                      "beyond what the contact law allows (time step too "
                                      "large or grains placed overlapping)",
                                      kMaxContacts)};
    if (bond_lost_ < n)
      return parts::Fault{id_[bond_lost_],
                          fmt::format("a bonded pair separated by more than {} x the largest "
                                      "radius without the bond breaking: its strength is far "
                                      "above what its stiffness allows",
                                      2 * kBondReach)};
    const Index bad = unhealthy_;  // note_health
    if (bad >= n) return std::nullopt;
    const Index i = bad;
    if (!outflow_remove_ && !in_domain(i))
      return parts::Fault{id_[i], fmt::format("grain left the domain at x = ({}) m; enlarge "
                                              "[domain], add walls or set domain.outflow = "
                                              "\"remove\"",
                                              fmt::join(x_[i].data(), x_[i].data() + D, ", "))};
    if (!x_[i].allFinite())
      return parts::Fault{id_[i], fmt::format("non-finite position x = ({}) m",
                                              fmt::join(x_[i].data(), x_[i].data() + D, ", "))};
    return parts::Fault{id_[i], "non-finite force or torque"};
  }

  std::optional<parts::ContactPoints<D>> contact_points() const override {
    parts::ContactPoints<D> p;
    p.position = &x_;
    p.velocity = &v_;
    p.mass = &m_;
    p.radius = &r_;
    p.angular_velocity = &w_;
    p.surface_offset = &surface_offset_;
    p.surface_overlap = &surface_overlap_;
    return p;
  }

  // Forces of contacts with other parts join force_ and torque_ after the grains' own (local
  // damping acts on the grains' own unbalanced force only).
  void add_contact_forces(const std::vector<Vec<D>>& force,
                          const std::vector<AngularVec<D>>& torque) override {
    if (static_cast<Index>(force.size()) != f_.size() ||
        static_cast<Index>(torque.size()) != f_.size())
      throw std::logic_error("dem: contact forces for another grain count");
    if (contact_pending_ && last_dt_ > 0) {
      const Real half_dt = 0.5 * last_dt_;
      contact_work_ += parallel::deterministic_sum<Real>(f_.size(), [&](Index i) {
        return half_dt * (v_[i].dot(contact_force_[i] + force[i]) +
                          angular_dot<D>(w_[i], contact_torque_[i] + torque[i]));
      });
    }
    contact_pending_ = false;
    parallel::for_each(f_.size(), [&](Index i) {
      contact_force_[i] = force[i];
      contact_torque_[i] = torque[i];
      force_[i] += force[i];
      torque_[i] += torque[i];
      note_health(i);
    });
  }

  // check()'s test of grain i, made where its force is summed (grain_pass, and again when the
  // contacts with other parts add theirs): the first failing grain is kept.
  void note_health(Index i) {
    if (healthy(i)) return;
#pragma omp critical(crater_dem_overflow)
    unhealthy_ = std::min(unhealthy_, i);
  }

  void advance(Real /*t*/, Real dt) override {
    const Real half = 0.5 * dt;
    last_dt_ = dt;
    contact_pending_ = true;
    // One pass: kick, drift, the wall guard (reflect), the power of gravity at the new
    // velocities (before any reflection) and the largest squared displacement since the list
    // was built, which update_neighbors then needs not measure again.
    struct Pass {
      Real power = 0, reflections = 0, lost = 0, moved_sq = 0;
      Pass& operator+=(const Pass& o) {
        power += o.power;
        reflections += o.reflections;
        lost += o.lost;
        moved_sq = std::max(moved_sq, o.moved_sq);  // as VerletSkin::stale's max
        return *this;
      }
    };
    const bool gravity = gravity_.squaredNorm() > 0;
    const bool guard = !cfg_.walls.empty() || !cfg_.absorbing_walls.empty();
    const std::span<const Vec<D>> built = skin_.positions();
    const bool measure = built.size() == static_cast<std::size_t>(f_.size());
    const Pass sum = parallel::deterministic_sum<Pass>(f_.size(), [&](Index i) {
      Pass p;
      v_[i] += (half / m_[i]) * force_[i];
      w_[i] += (half / inertia_[i]) * torque_[i];
      x_[i] += dt * v_[i];
      if (gravity) p.power = m_[i] * gravity_.dot(v_[i]);
      if (guard) reflect_at_walls(i, p.reflections, p.lost);
      if (measure) p.moved_sq = (x_[i] - built[static_cast<std::size_t>(i)]).squaredNorm();
      return p;
    });
    if (gravity) external_work_ += dt * sum.power;
    if (guard) {
      wall_reflections_ += sum.reflections;
      contact_dissipated_ += sum.lost;
    }
    moved_sq_ = measure ? sum.moved_sq : -1;
  }

  // Safeguard: a grain driven through a wall (its centre beyond the face: an overlap of more
  // than its radius, which a blast can force against a Hertz wall) is put back, mirrored in the
  // face, with its normal velocity reversed and scaled by the wall's restitution; the kinetic
  // energy lost is booked as contact dissipation. Counted in wall_reflections.
  void reflect_at_walls(Index i, Real& count, Real& lost) {
    // Inside every face (x <= an upper plane, x >= a lower one): nothing to do.
    bool inside = true;
    for (int d = 0; d < D; ++d)
      inside &= x_[i][d] >= guard_lo_[d] && x_[i][d] <= guard_hi_[d];
    if (inside) return;
    for (const WallPlane& w : guard_planes_) {
      const int axis = w.axis;
      const bool upper = w.upper;
      const Real plane = w.plane;
      const Real beyond = upper ? x_[i][axis] - plane : plane - x_[i][axis];
      if (!(beyond > 0)) continue;
      x_[i][axis] = upper ? plane - beyond : plane + beyond;
      const Real vn = v_[i][axis];
      if ((upper && vn > 0) || (!upper && vn < 0)) {
        v_[i][axis] = -cfg_.wall_restitution * vn;
        lost += 0.5 * m_[i] * (1 - cfg_.wall_restitution * cfg_.wall_restitution) * vn * vn;
      }
      count += 1;
    }
  }

  void finish_step(Real dt) override {
    const Real half = 0.5 * dt;
    parallel::for_each(f_.size(), [&](Index i) {
      v_[i] += (half / m_[i]) * force_[i];
      w_[i] += (half / inertia_[i]) * torque_[i];
    });
    if (outflow_remove_) remove_outflow();
  }

  parts::Energies energies() const override {
    struct KE {
      Real k = 0, e = 0;
      KE& operator+=(const KE& o) {
        k += o.k;
        e += o.e;
        return *this;
      }
    };
    const KE s = parallel::deterministic_sum<KE>(f_.size(), [&](Index i) {
      return KE{0.5 * m_[i] * v_[i].squaredNorm() + angular_kinetic<D>(inertia_[i], w_[i]),
                elastic_[i]};
    });
    parts::Energies en;
    en.kinetic_j = s.k;
    // Stored in the springs + lost in contacts, minus the work of contacts with other parts.
    en.contact_j = s.e + contact_dissipated_ - contact_work_;
    en.damping_j = local_dissipated_;
    en.external_work_j = external_work_;
    en.eroded_j = left_energy_j_;
    return en;
  }

  parts::Geometry<D> geometry() const override {
    parts::Geometry<D> g;
    g.points = &x_;
    return g;
  }
  std::vector<fields::FieldView> point_fields() const override {
    return f_.views(kOutput);
  }

  std::vector<parts::Diagnostic> diagnostics() const override {
    std::vector<parts::Diagnostic> d = diagnostics_;
    if (!cfg_.walls.empty() || !cfg_.absorbing_walls.empty())
      d.push_back({"wall_reflections", wall_reflections_});
    if (cfg_.bonds.enabled) {
      d.push_back({"bonds_initial", static_cast<Real>(bonds_initial_)});
      d.push_back({"bonds_broken", bonds_broken_});
    }
    if (outflow_remove_) {
      d.push_back({"left_domain_count", static_cast<Real>(left_count_)});
      d.push_back({"left_domain_mass_kg", left_mass_kg_});
      d.push_back({"left_domain_energy_j", left_energy_j_});
    }
    return d;
  }
  void add_diagnostic(std::string name, Real value) {
    diagnostics_.push_back({std::move(name), value});
  }

  /// The grains in id order (positions and radii).
  std::vector<Grain<D>> grains() const {
    std::vector<Grain<D>> g(static_cast<std::size_t>(f_.size()));
    for (Index i = 0; i < f_.size(); ++i)
      g[static_cast<std::size_t>(id_[i])] = {x_[i], r_[i]};
    return g;
  }

  /// Mean kinetic energy per grain, and m g r of the mean grain (the settling scale).
  std::pair<Real, Real> settling_measure() const {
    const Index n = f_.size();
    const Real k = energies().kinetic_j / static_cast<Real>(std::max<Index>(n, 1));
    const Real m = mass_kg() / static_cast<Real>(std::max<Index>(n, 1));
    const Real r = parallel::deterministic_sum<Real>(n, [&](Index i) { return r_[i]; }) /
                   static_cast<Real>(std::max<Index>(n, 1));
    return {k, m * gravity_.norm() * r};
  }

 private:
  // The bed's impedance behind the absorbing walls (defaults from the grains, see the schema)
  // and each touching grain's static reaction: the rigid wall law's elastic normal force at its
  // overlap now (t = 0: after settling, or as placed).
  void init_absorbing_walls(const PartSettings& settings) {
    const Index n = f_.size();
    Real mass = 0, radius = 0;
    for (Index i = 0; i < n; ++i) {
      mass += m_[i];
      radius += r_[i];
    }
    const Real grains = static_cast<Real>(std::max<Index>(n, 1));
    const Real rho = cfg_.absorbing_density_kg_m3 > 0
                         ? cfg_.absorbing_density_kg_m3
                         : mass / region_volume<D>(settings.part.region);
    Real cp = cfg_.absorbing_p_wave_speed_m_s;
    if (!(cp > 0)) {
      if (cfg_.contact != ContactLawKind::LinearSpring)
        throw std::logic_error("absorbing walls with Hertz contacts need a P-wave speed");
      // A chain (square/cubic lattice) of the mean grain: 2r sqrt(k_n / m).
      cp = 2 * (radius / grains) * std::sqrt(cfg_.normal_stiffness_n_m / (mass / grains));
    }
    const Real nu = settings.grain.poisson_ratio;
    const Real cs = cfg_.absorbing_s_wave_speed_m_s > 0
                        ? cfg_.absorbing_s_wave_speed_m_s
                        : cp * std::sqrt((1 - 2 * nu) / (2 - 2 * nu));
    absorbing_ =
        AbsorbingWallParams{.normal_impedance = rho * cp, .tangential_impedance = rho * cs};
    add_diagnostic("absorbing_wall_density_kg_m3", rho);
    add_diagnostic("absorbing_wall_p_wave_speed_m_s", cp);
    add_diagnostic("absorbing_wall_s_wave_speed_m_s", cs);
    std::visit(
        [&](const auto& laws) {
          using Law = typename std::decay_t<decltype(laws)>::Type;
          for (Index i = 0; i < n; ++i)
            for (const parts::Face face : cfg_.absorbing_walls) {
              const WallPlane w = wall_plane(face);
              Vec<D> foot = x_[i];
              foot[w.axis] = w.plane;
              const ContactGeometry<D> g = sphere_wall_geometry<D>(x_[i], r_[i], foot);
              if (!g.touching()) continue;
              const ContactForce<D> cf =
                  evaluate_contact<D, Law>(laws.wall, g, RelativeVelocity<D>{}, m_[i],
                                           row_pitch(r_[i], r_[i]), Vec<D>::Zero(), Real(0));
              static_reaction_[i][w.axis] = std::max(cf.normal_force, Real(0));
            }
        },
        laws_);
  }

  bool in_domain(Index i) const {
    for (int d = 0; d < D; ++d)
      if (!(x_[i][d] >= domain_lo_[d] && x_[i][d] <= domain_hi_[d])) return false;
    return true;
  }
  bool healthy(Index i) const {
    return force_[i].allFinite() && angular_finite<D>(torque_[i]) &&
           (outflow_remove_ ? x_[i].allFinite() : in_domain(i));
  }

  // outflow = "remove": grains beyond the domain box leave the model at the end of the step,
  // with the velocities of t + dt. What they carried goes to eroded_j, so the balance still
  // closes: their kinetic and rotational energy, and the energy stored in their contacts and
  // bonds (elastic_ of the grains they end with), which would otherwise vanish from contact_j.
  // The rest keep their order (compaction in index order) and their contact and bond histories
  // (packed, less the slots keyed by a removed grain); the list is rebuilt at the next force
  // stage: the same numbers for any thread count, and after a restart from this state.
  void remove_outflow() {
    const Index n = f_.size();
    keep_.resize(static_cast<std::size_t>(n));
    const Index leaving = parallel::deterministic_sum<Index>(n, [&](Index i) {
      keep_[static_cast<std::size_t>(i)] = in_domain(i);
      return static_cast<Index>(!keep_[static_cast<std::size_t>(i)]);
    });
    if (leaving == 0) return;
    struct Left {
      Real mass = 0, energy = 0;
      Left& operator+=(const Left& o) {
        mass += o.mass;
        energy += o.energy;
        return *this;
      }
    };
    const Left left = parallel::deterministic_sum<Left>(n, [&](Index i) {
      if (!keep_[static_cast<std::size_t>(i)])
        return Left{m_[i], 0.5 * m_[i] * v_[i].squaredNorm() +
                               angular_kinetic<D>(inertia_[i], w_[i]) + elastic_[i]};
      // A staying grain's contacts and bonds with leaving ones: the energy of those it owns
      // leaves with them (the others' is in the leaving grain's elastic_), and their forces
      // leave its force_ and torque_ (undoing grain_pass), so that the next half kick owes
      // nothing to a removed grain (exactly so without local damping, which acted on the sum).
      Real lost = 0;
      const auto own_first = static_cast<std::size_t>(pair_begin_[static_cast<std::size_t>(i)]);
      const auto own_last = static_cast<std::size_t>(pair_begin_[static_cast<std::size_t>(i) + 1]);
      for (std::size_t k = own_first; k < own_last; ++k) {
        if (keep_[static_cast<std::size_t>(pair_j_[k])]) continue;
        const std::uint8_t flags = cache_.flags[k];
        if (flags) lost += cache_.elastic[k];
        if (flags & kContactOn) {
          force_[i] -= cache_.contact[k].f1;
          torque_[i] -= cache_.t1[k];
          contacts_[i] -= 1;  // it counts the contacts it owns (and its walls)
        }
        if (flags & kBondOn) {
          force_[i] -= cache_.bond_f1[k];
          torque_[i] -= cache_.bond_t1[k];
          bonds_[i] -= 1;
        }
      }
      const auto first = static_cast<std::size_t>(recv_begin_[static_cast<std::size_t>(i)]);
      const auto last = static_cast<std::size_t>(recv_begin_[static_cast<std::size_t>(i) + 1]);
      for (std::size_t e = first; e < last; ++e) {
        const auto k = static_cast<std::size_t>(recv_pair_[e]);
        if (keep_[static_cast<std::size_t>(pair_owner(k))]) continue;
        const std::uint8_t flags = cache_.flags[k];
        if (flags & kContactOn) {
          force_[i] += cache_.contact[k].f1;
          torque_[i] -= cache_.contact[k].t2;
        }
        if (flags & kBondOn) {
          force_[i] += cache_.bond_f1[k];
          torque_[i] -= cache_.bond_t2[k];
          bonds_[i] -= 1;
        }
      }
      elastic_[i] -= lost;
      return Left{0, lost};
    });
    if (left_count_ == 0)
      spdlog::info(
          "part '{}': grains leave the domain from t = {:.6g} s on and are removed "
          "(domain.outflow = \"remove\"; left_domain_* in summary.json)",
          name_, time_s_);
    left_count_ += leaving;
    left_mass_kg_ += left.mass;
    left_energy_j_ += left.energy;

    std::vector<std::int64_t> gone;  // ids of the leaving grains, sorted
    for (Index i = 0; i < n; ++i)
      if (!keep_[static_cast<std::size_t>(i)]) gone.push_back(id_[i]);
    std::sort(gone.begin(), gone.end());
    if (!packed_) pack_history(partner_, xi_, roll_);
    packed_ = true;
    compact_slots(partner_, gone, xi_, roll_);
    compact_slots(bond_partner_, gone, bond_);
    const Index kept = f_.compact(keep_);
    if (!bond_partner_new_.empty()) {  // scratch of the next pair pass
      bond_partner_new_.assign(static_cast<std::size_t>(kept) * kMaxContacts, kNoContact);
      bond_new_.assign(static_cast<std::size_t>(kept) * kMaxContacts, ParallelBondState<D>{});
    }
    const std::size_t wall_slots = static_cast<std::size_t>(kept) * cfg_.walls.size();
    wall_xi_.assign(wall_slots, Vec<D>::Zero());
    if (!wall_roll_.empty()) wall_roll_.assign(wall_slots, angular_zero<D>());
    wall_live_.assign(static_cast<std::size_t>(kept), 0);
    skin_.invalidate();
  }

  // The kMaxContacts slots of each kept grain (keep_), in order, less the slots keyed by a
  // grain in `gone` (its contacts and bonds end with it); the others move up, so that a grain's
  // slots stay filled from the first. `payload` moves with `key` (empty vectors: models that
  // are off).
  template <class... Payload>
  void compact_slots(std::vector<std::int64_t>& key, std::span<const std::int64_t> gone,
                     std::vector<Payload>&... payload) {
    if (key.empty()) return;
    constexpr auto slots = static_cast<std::size_t>(kMaxContacts);
    std::size_t out = 0;  // the first slot of the next kept grain; never past the one read
    for (std::size_t i = 0; i < keep_.size(); ++i) {
      if (!keep_[i]) continue;
      std::size_t k = out;
      for (std::size_t s = 0; s < slots; ++s) {
        const std::size_t from = i * slots + s;
        const std::int64_t p = key[from];
        if (p == kNoContact) break;
        if (std::binary_search(gone.begin(), gone.end(), p)) continue;
        key[k] = p;
        ((payload.empty() ? void() : void(payload[k] = payload[from])), ...);
        ++k;
      }
      for (; k < out + slots; ++k) {
        key[k] = kNoContact;
        ((payload.empty() ? void() : void(payload[k] = blank<Payload>())), ...);
      }
      out += slots;
    }
    key.resize(out);
    ((payload.empty() ? void() : payload.resize(out)), ...);
  }
  template <class T>
  static T blank() {
    if constexpr (std::is_same_v<T, Vec<D>>)
      return Vec<D>::Zero();
    else if constexpr (std::is_same_v<T, AngularVec<D>>)
      return angular_zero<D>();
    else
      return T{};
  }

  // A rigid face of the domain box as the loops use it.
  struct WallPlane {
    int axis = 0;
    bool upper = false;  // the face at domain_hi_ (else domain_lo_)
    Real plane = 0;      // its coordinate on the axis [m]
  };
  WallPlane wall_plane(parts::Face face) const {
    WallPlane w;
    w.axis = static_cast<int>(face) / 2;
    w.upper = static_cast<int>(face) % 2 == 1;
    w.plane = w.upper ? domain_hi_[w.axis] : domain_lo_[w.axis];
    return w;
  }

  // The pitch of evaluate_contact: r_1 + r_2 (a wall: r_1 = r_2 = r) with hertz_2d =
  // "row_of_spheres", else 0 (the law as it is).
  Real row_pitch(Real r1, Real r2) const {
    return rows_ ? r1 + r2 : Real(0);
  }

  // The grain that owns pair k (a binary search in pair_begin_; outflow only).
  Index pair_owner(std::size_t k) const {
    const auto it = std::upper_bound(pair_begin_.begin(), pair_begin_.end(), static_cast<Index>(k));
    return static_cast<Index>(it - pair_begin_.begin()) - 1;
  }

  // Slot of `partner` in grain i's packed history (partner_), or -1.
  int find_slot(Index owner, std::int64_t partner) const {
    const std::size_t base = static_cast<std::size_t>(owner) * kMaxContacts;
    // Slots are filled from the first, the rest hold kNoContact: stop at the first empty one.
    for (int k = 0; k < kMaxContacts; ++k) {
      const std::int64_t p = partner_[base + static_cast<std::size_t>(k)];
      if (p == partner) return k;
      if (p == kNoContact) break;
    }
    return -1;
  }

  // Contact histories live with the contacts while the list stands: per owned pair (pair_xi_,
  // pair_roll_) and per grain and wall (wall_xi_, wall_roll_), updated in place by the one
  // thread that evaluates the contact, as LAMMPS keeps its history with the neighbour list. At
  // a rebuild (and in a restart file) they are packed into kMaxContacts slots per grain keyed
  // by the partner's id (partner_, xi_, roll_; walls: -1 - face), which survive the re-sort,
  // and unpacked into the new list. A contact that is not touching holds a zero history.
  //
  // pack_history: live contacts of grain i in the order pair_pass and grain_pass meet them
  // (owned pairs in list order, then walls).
  void pack_history(std::vector<std::int64_t>& partner, std::vector<Vec<D>>& xi,
                    std::vector<AngularVec<D>>& roll) const {
    const Index n = f_.size();
    // Sized here, filled below per grain (its slots past the last contact emptied there).
    partner.resize(static_cast<std::size_t>(n) * kMaxContacts);
    xi.resize(static_cast<std::size_t>(n) * kMaxContacts);
    if (rolling_.friction > 0)
      roll.resize(static_cast<std::size_t>(n) * kMaxContacts);
    else
      roll.clear();
    const bool pairs = static_cast<Index>(pair_begin_.size()) == n + 1;
    const std::size_t walls = cfg_.walls.size();
    parallel::for_each(n, [&](Index i) {
      const std::size_t base = static_cast<std::size_t>(i) * kMaxContacts;
      std::size_t k = 0;
      auto put = [&](std::int64_t key, const Vec<D>& h, const AngularVec<D>& r) {
        if (k == kMaxContacts) return;  // only after an overflow fault (check())
        partner[base + k] = key;
        xi[base + k] = h;
        if (!roll.empty()) roll[base + k] = r;
        ++k;
      };
      if (pairs)
        for (Index p = pair_begin_[static_cast<std::size_t>(i)];
             p < pair_begin_[static_cast<std::size_t>(i) + 1]; ++p) {
          const auto q = static_cast<std::size_t>(p);
          if (!(cache_.flags[q] & kContactOn)) continue;
          put(id_[pair_j_[q]], pair_xi_[q], pair_roll_.empty() ? angular_zero<D>() : pair_roll_[q]);
        }
      for (std::size_t w = 0; w < walls; ++w) {
        const std::size_t at = static_cast<std::size_t>(i) * walls + w;
        if (!(wall_live_[static_cast<std::size_t>(i)] >> w & 1u)) continue;
        put(-1 - static_cast<std::int64_t>(cfg_.walls[w]), wall_xi_[at],
            wall_roll_.empty() ? angular_zero<D>() : wall_roll_[at]);
      }
      for (; k < static_cast<std::size_t>(kMaxContacts); ++k) {
        partner[base + k] = kNoContact;
        xi[base + k] = Vec<D>::Zero();
        if (!roll.empty()) roll[base + k] = angular_zero<D>();
      }
    });
  }
  // The histories of partner_, xi_, roll_ into the pairs of the current list and the walls.
  void unpack_history() {
    const Index n = f_.size();
    const std::size_t walls = cfg_.walls.size();
    parallel::for_each(n, [&](Index i) {
      const std::size_t base = static_cast<std::size_t>(i) * kMaxContacts;
      for (Index p = pair_begin_[static_cast<std::size_t>(i)];
           p < pair_begin_[static_cast<std::size_t>(i) + 1]; ++p) {
        const auto q = static_cast<std::size_t>(p);
        const int k = find_slot(i, id_[pair_j_[q]]);
        // Live: the flag pack_history reads, until pair_pass sets it again.
        cache_.flags[q] = k < 0 ? 0 : kContactOn;
        pair_xi_[q] = k < 0 ? Vec<D>::Zero() : xi_[base + static_cast<std::size_t>(k)];
        if (!pair_roll_.empty())
          pair_roll_[q] = k < 0 ? angular_zero<D>() : roll_[base + static_cast<std::size_t>(k)];
      }
      wall_live_[static_cast<std::size_t>(i)] = 0;
      for (std::size_t w = 0; w < walls; ++w) {
        const std::size_t at = static_cast<std::size_t>(i) * walls + w;
        const int k = find_slot(i, -1 - static_cast<std::int64_t>(cfg_.walls[w]));
        if (k >= 0) wall_live_[static_cast<std::size_t>(i)] |= 1u << w;
        wall_xi_[at] = k < 0 ? Vec<D>::Zero() : xi_[base + static_cast<std::size_t>(k)];
        if (!wall_roll_.empty())
          wall_roll_[at] = k < 0 ? angular_zero<D>() : roll_[base + static_cast<std::size_t>(k)];
      }
    });
  }
  // Slot of the bond between `owner` and `partner` (last step's buffer), or -1.
  int find_bond(Index owner, std::int64_t partner) const {
    if (bond_partner_.empty()) return -1;
    const std::size_t base = static_cast<std::size_t>(owner) * kMaxContacts;
    for (int k = 0; k < kMaxContacts; ++k) {
      const std::int64_t p = bond_partner_[base + static_cast<std::size_t>(k)];
      if (p == partner) return k;
      if (p == kNoContact) break;
    }
    return -1;
  }

  // The law's parameters with the friction of paper section III-C at this contact's strain
  // rate |v_n| / (r_1 + r_2) (rate_dependent_friction.hpp; a wall: r_2 = 0).
  template <class Params>
  Params at_rate(const Params& p, const RateDependentFriction& rate, Real normal_velocity, Real r1,
                 Real r2) const {
    if (!cfg_.rate_dependent_friction) return p;
    Params q = p;
    q.friction = dynamic_friction_coefficient(rate, contact_strain_rate(normal_velocity, r1, r2));
    return q;
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

  // Counts a live contact of grain i (kMaxContacts at most: the packed history's capacity).
  void count_contact(Index i, PairTally& tally) {
    if (tally.slots == kMaxContacts) {
#pragma omp critical(crater_dem_overflow)
      overflow_ = std::min(overflow_, i);
      return;
    }
    ++tally.slots;
  }

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

  template <class Law>
  void pair_pass(Index first, Index last, Real dt, const LawPair<Law>& laws) {
    for (Index i = first; i < last; ++i)
      tally_[static_cast<std::size_t>(i)] = PairTally{};
    const bool bonds = !bond_partner_.empty();
    const Index end = pair_begin_[static_cast<std::size_t>(last)];
    std::array<Index, kScanChunk> near, owner_of;
    // Per thread, built once (a local array would zero its entries for every block).
    static thread_local std::array<Candidate<Law>, kScanChunk> cand;
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
        const bool close =
            bonds || (x_[owner] - x_[j]).squaredNorm() <= reach * reach * kTouchMargin;
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
        cand[at].prep = prepare_contact<D, Law>(
            laws.grain, cand[at].g, effective_mass(m_[i], m_[j]), row_pitch(r_[i], r_[j]),
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
  template <class Law>
  [[gnu::always_inline]] void pair_law(Index i, std::size_t k, const Candidate<Law>& cand, Real dt,
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
      const ContactForce<D> cf = finish_contact<D, Law>(
          at_rate(laws.grain, grain_rate_, rel.normal, r_i, r_[j]), g, rel, cand.prep, dt);
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
  void clear_pair(std::size_t k, std::uint8_t& flags) {
    if (flags & kContactOn) {
      cache_.contact[k] = ContactResult{};
      pair_xi_[k] = Vec<D>::Zero();
      if (!pair_roll_.empty()) pair_roll_[k] = angular_zero<D>();
    }
    flags = 0;
  }

  template <class Law>
  void grain_pass(Index i, Real dt, const LawPair<Law>& laws) {
    PairTally tally = tally_[static_cast<std::size_t>(i)];
    Vec<D> force = m_[i] * gravity_;
    AngularVec<D> torque = angular_zero<D>();
    const std::size_t base = static_cast<std::size_t>(i) * kMaxContacts;
    const bool rolling = rolling_.friction > 0;
    int bonds = tally.bonds;
    const auto first = static_cast<std::size_t>(recv_begin_[static_cast<std::size_t>(i)]);
    const auto last = static_cast<std::size_t>(recv_begin_[static_cast<std::size_t>(i) + 1]);
    if (scatter_) {
      Received& from = received_[static_cast<std::size_t>(i)];
      force = from.force;
      torque = from.torque;
      from = Received{m_[i] * gravity_, angular_zero<D>()};
    } else if (cache_.bond_f1.empty()) {
      // No bonds: every pair adds its share, zero when not in contact, with no branch. A sum
      // that starts at +0 or a non-zero value never becomes -0, so adding +-0 leaves it as
      // skipping would.
      for (std::size_t e = first; e < last; ++e) {
        const ContactResult& c = cache_.contact[static_cast<std::size_t>(recv_pair_[e])];
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
    Real elastic = tally.elastic, dissipated = tally.dissipated;

    const std::size_t walls = wall_planes_.size();
    // Grains in the interior (further than r_max from every wall) skip the walls.
    bool near_wall = false;
    const Real reach = r_max_ * kTouchMargin;
    for (int d = 0; d < D; ++d)
      near_wall |= !(x_[i][d] - clear_lo_[d] > reach && clear_hi_[d] - x_[i][d] > reach);
    std::uint32_t& live = wall_live_[static_cast<std::size_t>(i)];
    if (!near_wall && live)  // a wall contact left behind in one step (never in practice) ends
      for (std::size_t w = 0; w < walls; ++w)
        clear_wall(live, w, static_cast<std::size_t>(i) * walls + w);
    for (std::size_t w = 0; near_wall && w < walls; ++w) {
      const int axis = wall_planes_[w].axis;
      const Real plane = wall_planes_[w].plane;
      const std::size_t at = static_cast<std::size_t>(i) * walls + w;
      // The distance to the plane is |x_axis - plane|: grains clearly apart skip the geometry.
      if (std::abs(x_[i][axis] - plane) > r_[i] * kTouchMargin) {
        clear_wall(live, w, at);
        continue;
      }
      Vec<D> foot = x_[i];
      foot[axis] = plane;
      const ContactGeometry<D> g = sphere_wall_geometry<D>(x_[i], r_[i], foot);
      if (!g.touching()) {
        clear_wall(live, w, at);
        continue;
      }
      const RelativeVelocity<D> rel =
          relative_velocity<D>(g, BodyMotion<D>{v_[i], w_[i]}, BodyMotion<D>{});
      const ContactForce<D> cf =
          evaluate_contact<D, Law>(at_rate(laws.wall, wall_rate_, rel.normal, r_[i], Real(0)), g,
                                   rel, m_[i], row_pitch(r_[i], r_[i]), wall_xi_[at], dt);
      RollingTorque<D> rt;
      if (rolling)
        rt = rolling_resistance<D>(rolling_, g, rel,
                                   RollingLoad{.normal_force = cf.normal_force,
                                               .normal_stiffness = cf.normal_stiffness,
                                               .inertia_eff = rolling_inertia_eff_wall(
                                                   RollingBody{inertia_[i], m_[i], r_[i]})},
                                   wall_roll_[at], dt);
      force += cf.force_on_1;
      torque += cf.torque_on_1 + rt.torque_on_1;
      wall_xi_[at] = cf.shear_history;
      if (rolling) wall_roll_[at] = rt.history;
      live |= 1u << w;
      count_contact(i, tally);
      elastic += cf.elastic_energy + rt.elastic_energy;
      dissipated += cf.dissipated_power + rt.dissipated_power;
    }
    // Absorbing walls: the held static reaction plus dashpots (absorbing_wall.hpp).
    Real absorbed = 0, static_power = 0;
    for (const parts::Face face : cfg_.absorbing_walls) {
      const WallPlane w = wall_plane(face);
      Vec<D> foot = x_[i];
      foot[w.axis] = w.plane;
      const ContactGeometry<D> g = sphere_wall_geometry<D>(x_[i], r_[i], foot);
      if (!g.touching()) continue;
      const AbsorbingWallForce<D> aw = absorbing_wall_force<D>(
          absorbing_, absorbing_wall_area<D>(r_[i]), g.normal, v_[i], static_reaction_[i][w.axis]);
      force += aw.force;
      absorbed += aw.dissipated_power;
      static_power += aw.static_power;
    }
    if (!bond_partner_new_.empty()) {
      for (int k = tally.bond_slots; k < kMaxContacts; ++k)
        bond_partner_new_[base + static_cast<std::size_t>(k)] = kNoContact;
      // Every bond this grain owned must have been met in the list (kBondReach).
      int owned = 0;
      for (int k = 0; k < kMaxContacts; ++k)
        owned += bond_partner_[base + static_cast<std::size_t>(k)] != kNoContact;
      if (tally.bonds_seen != owned) {
#pragma omp critical(crater_dem_overflow)
        bond_lost_ = std::min(bond_lost_, i);
      }
    }

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
    // Fields of models that are off stay zero, unwritten (compute_forces does not read them).
    if (cfg_.local_damping > 0 || !cfg_.absorbing_walls.empty()) {
      local_power_[i] = local_power;
      static_power_[i] = static_power;
    }
    if (!bond_partner_.empty()) {
      bonds_[i] = bonds;
      bond_breaks_[i] = tally.breaks;
      bond_released_[i] = tally.released;
    }
  }
  // Wall w of a grain with live-contact bits `live` (history slot at): no contact, no history.
  void clear_wall(std::uint32_t& live, std::size_t w, std::size_t at) {
    if (!(live >> w & 1u)) return;
    live &= ~(1u << w);
    wall_xi_[at] = Vec<D>::Zero();
    if (!wall_roll_.empty()) wall_roll_[at] = angular_zero<D>();
  }

  // Parallel bonds at t = 0 between the grains whose surface gap is at most gap_fraction x the
  // smaller radius, held by the lower id (both buffers, so the first step reads them).
  void make_bonds() {
    const Index n = f_.size();
    bond_partner_.assign(static_cast<std::size_t>(n) * kMaxContacts, kNoContact);
    bond_.assign(static_cast<std::size_t>(n) * kMaxContacts, ParallelBondState<D>{});
    update_neighbors();
    const BondRadiusRule rule = bond_rule(cfg_.bonds.radius_rule);
    for (Index i = 0; i < n; ++i) {
      int k = 0;
      for (const Index j : list_.of(i)) {
        const Real gap = (x_[i] - x_[j]).norm() - r_[i] - r_[j];
        if (gap > cfg_.bonds.gap_fraction * std::min(r_[i], r_[j])) continue;
        ++bonds_[i];
        if (id_[i] > id_[j]) continue;
        if (k == kMaxContacts)
          throw std::runtime_error(
              fmt::format("part '{}': grain {} has more than {} bonds (grains placed overlapping?)",
                          name_, id_[i], kMaxContacts));
        const std::size_t at =
            static_cast<std::size_t>(i) * kMaxContacts + static_cast<std::size_t>(k++);
        bond_partner_[at] = id_[j];
        bond_[at] = parallel_bond_state<D>(
            parallel_bond_radius(rule, cfg_.bonds.radius_multiplier, r_[i], r_[j]));
        ++bonds_initial_;
      }
    }
    bond_partner_new_ = bond_partner_;
    bond_new_ = bond_;
  }

  // Verlet list with a skin, as in the SPH part; grains are re-sorted at each rebuild and the
  // history slots move with them.
  void update_neighbors() {
    const Real need = 2 * r_max_ * (cfg_.bonds.enabled ? 1 + kBondReach : 1);
    // advance measured the displacement; at the start and after a restart it is measured here.
    const bool stale = moved_sq_ >= 0 ? skin_.stale_given(moved_sq_, f_.size(), need)
                                      : skin_.stale(std::span<const Vec<D>>(x_), need);
    moved_sq_ = -1;
    if (!stale) return;
    if (!packed_) pack_history(partner_, xi_, roll_);
    packed_ = true;
    const auto order =
        neighbors::cell_sort_order<D>(std::span<const Vec<D>>(x_), need * (1 + kSkin));
    f_.permute(order);
    permute_slots(order);
    skin_.built(std::span<const Vec<D>>(x_), need);
    build_lists();
  }

  // The list for the positions of the last rebuild (after a restart: the saved ones, which
  // gives the very list the interrupted run used), its owned pairs, and the packed histories
  // unpacked into them.
  void build_lists() {
    neighbors::build_neighbor_list<D>(skin_.positions(), skin_.radius(), neighbors::Pairs::Full,
                                      list_);
    const Index n = list_.size();
    // Owned pairs: the entries (i, j) with id_i < id_j, per grain in list order.
    pair_begin_.assign(static_cast<std::size_t>(n) + 1, 0);
    parallel::for_each(n, [&](Index i) {
      Index owned = 0;
      for (const Index j : list_.of(i))
        owned += id_[i] < id_[j];
      pair_begin_[static_cast<std::size_t>(i) + 1] = owned;
    });
    for (Index i = 0; i < n; ++i)
      pair_begin_[static_cast<std::size_t>(i) + 1] += pair_begin_[static_cast<std::size_t>(i)];
    pair_j_.resize(static_cast<std::size_t>(pair_begin_.back()));
    recv_begin_.assign(static_cast<std::size_t>(n) + 1, 0);
    parallel::for_each(n, [&](Index i) {
      Index p = pair_begin_[static_cast<std::size_t>(i)];
      for (const Index j : list_.of(i))
        if (id_[i] < id_[j]) pair_j_[static_cast<std::size_t>(p++)] = j;
      recv_begin_[static_cast<std::size_t>(i) + 1] =
          static_cast<Index>(list_.of(i).size()) -
          (pair_begin_[static_cast<std::size_t>(i) + 1] - pair_begin_[static_cast<std::size_t>(i)]);
    });
    for (Index i = 0; i < n; ++i)
      recv_begin_[static_cast<std::size_t>(i) + 1] += recv_begin_[static_cast<std::size_t>(i)];
    // The pairs (j, i) that grain i receives (pairs are ascending in j's
    // row: binary search).
    recv_pair_.resize(pair_j_.size());
    parallel::for_each(n, [&](Index i) {
      Index e = recv_begin_[static_cast<std::size_t>(i)];
      for (const Index j : list_.of(i)) {
        if (id_[i] < id_[j]) continue;
        const auto b = pair_j_.begin() + pair_begin_[static_cast<std::size_t>(j)];
        const auto it =
            std::lower_bound(b, pair_j_.begin() + pair_begin_[static_cast<std::size_t>(j) + 1], i);
        recv_pair_[static_cast<std::size_t>(e++)] = static_cast<Index>(it - pair_j_.begin());
      }
      // In pair order: the order in which a single thread meets them (scatter_).
      std::sort(recv_pair_.begin() + recv_begin_[static_cast<std::size_t>(i)],
                recv_pair_.begin() + e);
    });
    scatter_ = parallel::max_threads() == 1 && bond_partner_.empty() && !outflow_remove_;
    received_.clear();
    if (scatter_) {
      received_.resize(static_cast<std::size_t>(n));
      for (Index i = 0; i < n; ++i)
        received_[static_cast<std::size_t>(i)].force = m_[i] * gravity_;
    }
    const auto pairs = pair_j_.size();
    cache_.resize(pairs, !bond_partner_.empty(), outflow_remove_);
    pair_xi_.resize(pairs);
    pair_roll_.resize(rolling_.friction > 0 ? pairs : 0);
    tally_.resize(static_cast<std::size_t>(n));
    unpack_history();
    packed_ = false;
  }

 public:
  void save_state(parts::StateWriter& w) const override {
    w.tag("dem");
    f_.save(w);
    if (packed_) {
      w.vector(partner_);
      w.vector(xi_);
      w.vector(roll_);
    } else {
      std::vector<std::int64_t> partner;
      std::vector<Vec<D>> xi;
      std::vector<AngularVec<D>> roll;
      pack_history(partner, xi, roll);
      w.vector(partner);
      w.vector(xi);
      w.vector(roll);
    }
    w.vector(bond_partner_);
    w.vector(bond_);
    w.value(last_dt_);
    w.value(bond_lost_);
    w.value(bonds_initial_);
    w.value(bonds_broken_);
    w.value(external_work_);
    w.value(contact_dissipated_);
    w.value(local_dissipated_);
    w.value(contact_work_);
    w.value(contact_pending_);
    w.value(wall_reflections_);
    skin_.save(w);
    w.tag("outflow");
    w.value(left_count_);
    w.value(left_mass_kg_);
    w.value(left_energy_j_);
  }
  void load_state(parts::StateReader& r) override {
    r.tag("dem");
    moved_sq_ = -1;  // measured again at the next force stage
    f_.load(r);
    r.vector(partner_);
    r.vector(xi_);
    r.vector(roll_);
    packed_ = true;
    r.vector(bond_partner_);
    r.vector(bond_);
    r.value(last_dt_);
    r.value(bond_lost_);
    r.value(bonds_initial_);
    r.value(bonds_broken_);
    r.value(external_work_);
    r.value(contact_dissipated_);
    r.value(local_dissipated_);
    r.value(contact_work_);
    r.value(contact_pending_);
    r.value(wall_reflections_);
    skin_.load(r);
    r.tag("outflow");
    r.value(left_count_);
    r.value(left_mass_kg_);
    r.value(left_energy_j_);
    if (skin_.radius() > 0) build_lists();
  }

 private:
  void permute_slots(std::span<const Index> order) {
    permute_blocks(partner_, order);
    permute_blocks(xi_, order);
    permute_blocks(roll_, order);
    permute_blocks(bond_partner_, order);
    permute_blocks(bond_, order);
  }
  // Moves the kMaxContacts slots of each grain with it (empty vectors: models that are off).
  template <class T>
  static void permute_blocks(std::vector<T>& slots, std::span<const Index> order) {
    if (slots.empty()) return;
    const std::vector<T> copy = slots;
    parallel::for_each(static_cast<Index>(order.size()), [&](Index i) {
      const auto to = static_cast<std::size_t>(i) * kMaxContacts;
      const auto from = static_cast<std::size_t>(order[static_cast<std::size_t>(i)]) * kMaxContacts;
      for (std::size_t k = 0; k < static_cast<std::size_t>(kMaxContacts); ++k)
        slots[to + k] = copy[from + k];
    });
  }

  std::string name_;
  Settings cfg_;
  Vec<D> gravity_, domain_lo_, domain_hi_;
  bool outflow_remove_ = false;  // domain.outflow = "remove" (remove_outflow)
  Real rho_ = 0, shear_modulus_ = 0, poisson_ = 0;
  ContactLaws laws_;
  RollingResistanceParams rolling_;
  RateDependentFriction grain_rate_, wall_rate_;
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
  std::vector<Real>& surface_offset_;   // parts::ContactPoints::surface_offset
  std::vector<Real>& surface_overlap_;  // parts::ContactPoints::surface_overlap
  Real contact_work_ = 0;               // work of those forces on the grains [J]
  Real wall_reflections_ = 0;           // grains put back from beyond a wall (reflect_at_walls)
  bool contact_pending_ = false;        // moved since they were set
  AbsorbingWallParams absorbing_;

  // Contact history packed at rebuilds: kMaxContacts slots per grain (partner id, tangential
  // spring, rolling moment; pack_history), authoritative while packed_.
  std::vector<std::int64_t> partner_;
  std::vector<Vec<D>> xi_;
  std::vector<AngularVec<D>> roll_;  // rolling moments (empty when mu_r = 0)
  bool packed_ = true;
  // ... and while the list stands: per owned pair and per grain and wall (cfg_.walls order).
  std::vector<Vec<D>> pair_xi_, wall_xi_;
  std::vector<AngularVec<D>> pair_roll_, wall_roll_;  // empty when mu_r = 0
  std::vector<std::uint32_t> wall_live_;  // per grain: bit w, a live contact with wall w
  // The faces of cfg_.walls; with cfg_.absorbing_walls (reflect_at_walls); the box beyond whose
  // planes (r_max away) a grain touches no face of cfg_.walls (+-inf where there is none).
  std::vector<WallPlane> wall_planes_, guard_planes_;
  Vec<D> clear_lo_, clear_hi_;
  Vec<D> guard_lo_, guard_hi_;  // inside these bounds a grain is beyond no face (reflect_at_walls)
  // Bonds: kMaxContacts slots per grain (partner id of higher id, state); empty without bonds.
  std::vector<std::int64_t> bond_partner_, bond_partner_new_;
  std::vector<ParallelBondState<D>> bond_, bond_new_;

  neighbors::NeighborList list_;
  // Owned pairs (i, j), id_i < id_j: grain i's at pair_begin_[i] .. pair_begin_[i + 1], j in
  // pair_j_; per list entry, its pair: 2 p if the row's grain owns it, else 2 p + 1.
  std::vector<Index> pair_begin_, pair_j_;     // owned pairs (i, j) of grain i, in list order
  std::vector<Index> recv_begin_, recv_pair_;  // pairs (j, i) that grain i receives, likewise
  PairCache cache_;                            // per owned pair: the contact's results (pair_pass)
  bool scatter_ = false;                       // one thread: received shares summed in pair_pass
  std::vector<Received> received_;             // per grain, with scatter_
  // The largest squared displacement since the list's build, measured by advance; -1: unknown.
  Real moved_sq_ = -1;
  std::vector<PairTally> tally_;
  neighbors::VerletSkin<D> skin_{kSkin};
  Real last_dt_ = 0;
  // 2D hertz_mindlin with hertz_2d = "row_of_spheres" (evaluate_contact).
  bool rows_ = false;
  Index overflow_ = 0, bond_lost_ = 0;
  Index unhealthy_ = 0;  // the first grain check() fails (note_health), else the count
  Index bonds_initial_ = 0;
  Real bonds_broken_ = 0;
  Real external_work_ = 0, contact_dissipated_ = 0, local_dissipated_ = 0;
  std::vector<parts::Diagnostic> diagnostics_;
  // Grains removed beyond the domain box (outflow = "remove"): how many, their mass [kg] and
  // the energy booked with them [J] (eroded_j).
  Index left_count_ = 0;
  Real left_mass_kg_ = 0, left_energy_j_ = 0;
  std::vector<std::uint8_t> keep_;  // scratch: remove_outflow's mask
  Real time_s_ = 0;                 // of the last force stage, for the log
};

}  // namespace

// Everything that shapes a settled packing, as text for its cache key (hex floats: exact).
template <int D>
std::string packing_key_text(const PartSettings& settings) {
  const parts::PartSetup& pc = settings.part;
  std::string s = fmt::format("crater packing v2|D={}|", D);
  auto v3 = [](const parts::Vec3& v) { return fmt::format("{:a},{:a},{:a}", v[0], v[1], v[2]); };
  const auto& g = settings.grain;
  s += fmt::format("domain={};{};g={}|", v3(pc.domain.min_m), v3(pc.domain.max_m),
                   v3(pc.domain.gravity_m_s2));
  s += fmt::format("mat={:a},{:a},{:a},{:a},{:a}|", settings.rho0_kg_m3, g.shear_modulus_pa,
                   g.poisson_ratio, g.friction, g.restitution);
  s += fmt::format("region={},{},{},{},{:a}|spacing={:a}|", static_cast<int>(pc.region.type),
                   v3(pc.region.min_m), v3(pc.region.max_m), v3(pc.region.center_m),
                   pc.region.radius_m, pc.spacing_m);
  const auto& d = settings.dem;
  s += fmt::format("dem={:a},{:a},{},{:a},{:a},{:a}|walls=", d.radius_min_m, d.radius_max_m, d.seed,
                   d.rayleigh_fraction, d.wall_friction, d.wall_restitution);
  for (const auto f : d.walls)
    s += fmt::format("{},", static_cast<int>(f));
  // Absorbing faces are rigid walls while settling (listed only when there are some, so the
  // keys of packings without them are unchanged).
  if (!d.absorbing_walls.empty()) {
    s += "|absorbing=";
    for (const auto f : d.absorbing_walls)
      s += fmt::format("{},", static_cast<int>(f));
  }
  s += fmt::format("|law={},{:a},{:a},{:a},{:a},{:a},{},{:a},{:a}", static_cast<int>(d.contact),
                   d.normal_stiffness_n_m, d.shear_stiffness_n_m, d.stiffness_step_fraction,
                   d.rolling_friction, d.rolling_damping, d.rate_dependent_friction,
                   d.friction_rate_beta, d.friction_reference_strain_rate);
  if (d.hertz_row_of_spheres) s += "|hertz_2d=row_of_spheres";
  const auto& k = settings.packing;
  s += fmt::format("|packing={},{:a},{:a},{:a},{:a},{:a}|sieve=", k.random, k.porosity,
                   k.settle_kinetic_ratio, k.settle_max_time_s, k.settle_damping,
                   settings.safety_factor);
  for (std::size_t j = 0; j < k.sieve_diameter_m.size(); ++j)
    s += fmt::format("{:a}:{:a},", k.sieve_diameter_m[j], k.sieve_passing[j]);
  return s;
}

template <int D>
std::vector<Grain<D>> random_grains(const PartSettings& settings) {
  const parts::PartSetup& pc = settings.part;
  const auto& k = settings.packing;
  const std::string key_name = fmt::format("parts[{}].packing", pc.name);
  const Real solid = (1 - k.porosity) * region_volume<D>(pc.region);
  std::vector<Real> radii =
      draw_radii<D>(k, settings.dem.radius_min_m, settings.dem.radius_max_m, solid,
                    settings.dem.seed, std::size_t{50'000'000}, pc.where, key_name);
  return random_packing<D>(pc.region, std::move(radii), to_vec<D>(pc.domain.gravity_m_s2),
                           to_vec<D>(pc.domain.min_m), to_vec<D>(pc.domain.max_m),
                           settings.dem.seed, pc.where, key_name);
}

// Settle: the part alone under gravity, with its walls and the settling damping, until the
// grains have had the time to fall the column's height and their mean kinetic energy is
// below settle_kinetic_ratio x m g r.
template <int D>
std::vector<Grain<D>> settle_grains(const PartSettings& settings,
                                    const std::vector<Grain<D>>* grains, PackingReport& report) {
  const parts::PartSetup& pc = settings.part;
  const auto& k = settings.packing;
  const std::string key_name = fmt::format("parts[{}].packing", pc.name);
  DemPart<D> part(settings, grains, k.settle_damping);
  const Vec<D> g = to_vec<D>(pc.domain.gravity_m_s2);
  Real lo = std::numeric_limits<Real>::infinity(), hi = -lo;
  for (const auto& q : part.grains()) {
    lo = std::min(lo, q.x.dot(g) / g.norm());
    hi = std::max(hi, q.x.dot(g) / g.norm());
  }
  const Real t_fall = std::sqrt(2 * std::max(hi - lo, 0.0) / g.norm());
  spdlog::info("part '{}': settling {} grains under gravity (at least {:.3g} s)", pc.name,
               part.count(), t_fall);
  Real t = 0;
  long long steps = 0;
  part.compute_forces(t);
  while (true) {
    const Real dt = settings.safety_factor * part.stable_step().dt_s;
    part.advance(t, dt);
    t += dt;
    part.compute_forces(t);
    if (auto fault = part.check())
      throw InputError(pc.where, key_name,
                       fmt::format("settling failed at t = {:.4g} s, grain {}: {}", t,
                                   fault->entity_id, fault->what));
    part.finish_step(dt);
    ++steps;
    if (steps % 200 != 0 || t < t_fall) continue;
    const auto [ke, scale] = part.settling_measure();
    if (ke < k.settle_kinetic_ratio * scale) break;
    if (t > k.settle_max_time_s)
      throw InputError(pc.where, key_name + ".settle_max_time_s",
                       fmt::format("the grains did not settle in {} s: mean kinetic energy {:.3g} "
                                   "x m g r, settled below {:.3g}; raise settle_max_time_s or "
                                   "settle_damping",
                                   k.settle_max_time_s, ke / scale, k.settle_kinetic_ratio));
  }
  report.settle_time_s = t;
  report.settle_steps = steps;
  return part.grains();
}

template <int D>
std::unique_ptr<parts::Part<D>> make_dem_part(const PartSettings& settings,
                                              const std::vector<Grain<D>>* grains,
                                              const PackingReport& report) {
  if (!grains) return std::make_unique<DemPart<D>>(settings);
  const parts::PartSetup& part = settings.part;
  auto p = std::make_unique<DemPart<D>>(settings, grains);
  // Porosity of the packed grains over the region's cross-section times the bed's height
  // (box regions; along gravity), and how the packing was obtained.
  if (part.region.type == parts::RegionType::Box && !grains->empty()) {
    const Vec<D> g = to_vec<D>(part.domain.gravity_m_s2);
    int up = 0;
    for (int d = 1; d < D; ++d)
      if (std::abs(g[d]) > std::abs(g[up])) up = d;
    Real top = -std::numeric_limits<Real>::infinity(), bottom = -top, solid = 0;
    for (const auto& q : *grains) {
      top = std::max(top, q.x[up] + q.r);
      bottom = std::min(bottom, q.x[up] - q.r);
      solid += grain_volume<D>(q.r);
    }
    Real area = 1;
    for (int d = 0; d < D; ++d)
      if (d != up)
        area *= part.region.max_m[static_cast<std::size_t>(d)] -
                part.region.min_m[static_cast<std::size_t>(d)];
    p->add_diagnostic("packing_porosity", 1 - solid / (area * (top - bottom)));
    p->add_diagnostic("packing_bed_height_m", top - bottom);
  }
  if (settings.packing.settle) {
    p->add_diagnostic("packing_reused", report.reused ? 1.0 : 0.0);
    if (!report.reused) {
      p->add_diagnostic("settle_time_s", report.settle_time_s);
      p->add_diagnostic("settle_steps", static_cast<Real>(report.settle_steps));
    }
  }
  return p;
}

#define CRATER_DEM_PART(D)                                                                       \
  template std::string packing_key_text<D>(const PartSettings&);                                 \
  template std::vector<Grain<D>> random_grains<D>(const PartSettings&);                          \
  template std::vector<Grain<D>> settle_grains<D>(const PartSettings&,                           \
                                                  const std::vector<Grain<D>>*, PackingReport&); \
  template std::unique_ptr<parts::Part<D>> make_dem_part<D>(                                     \
      const PartSettings&, const std::vector<Grain<D>>*, const PackingReport&);
CRATER_DEM_PART(2)
CRATER_DEM_PART(3)
#undef CRATER_DEM_PART

}  // namespace crater::dem
