// The DEM part (dem_part_impl.hpp): construction, the step's stages around the force stage
// (advance, finish_step, the forces of contacts with other parts), the stable step, and the
// factory make_dem_part.
#include "dem/dem_part.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <span>
#include <stdexcept>
#include <variant>

#include "dem/dem_part_impl.hpp"
#include "parts/region.hpp"

namespace crater::dem {
namespace detail {
namespace {

using fields::kHalo;
using fields::kNone;
using fields::kOutput;
using fields::kRestart;
using fields::kStateRoles;
using parts::to_vec;

template <int D>
std::vector<AngularVec<D>>& add_angular(fields::FieldSet<D>& f, const char* name, const char* unit,
                                        unsigned roles) {
  if constexpr (D == 2)
    return f.add_scalar(name, unit, roles);
  else
    return f.add_vector(name, unit, roles);
}

// The grains a part starts from: centres, radii and velocities.
template <int D>
struct InitialGrains {
  std::vector<Vec<D>> pts;
  std::vector<Real> radii;
  std::vector<Vec<D>> vel;
};

// The grains are `grains` if given (a packing), else those placed by hand, else one per
// lattice site of the region (radii from the seed); less the carved parts' regions, with the
// random agitation unless `settling`.
template <int D>
InitialGrains<D> initial_grains(const PartSettings& settings, const std::vector<Grain<D>>* grains,
                                bool settling) {
  const parts::PartSetup& pc = settings.part;
  const Settings& cfg = settings.dem;
  InitialGrains<D> out;
  std::vector<Vec<D>>& pts = out.pts;
  std::vector<Real>& radii = out.radii;
  std::vector<Vec<D>>& vel = out.vel;
  if (grains) {
    for (const auto& q : *grains) {
      pts.push_back(q.x);
      radii.push_back(q.r);
      vel.push_back(to_vec<D>(pc.initial.velocity_m_s));
    }
  } else if (!cfg.particles.empty()) {
    for (const auto& q : cfg.particles) {
      pts.push_back(to_vec<D>(q.center_m));
      radii.push_back(q.radius_m);
      vel.push_back(to_vec<D>(q.velocity_m_s));
    }
  } else {
    pts = parts::region_lattice<D>(pc.region, pc.spacing_m);
    std::mt19937_64 rng(cfg.seed);
    std::uniform_real_distribution<Real> draw(cfg.radius_min_m, cfg.radius_max_m);
    for (std::size_t k = 0; k < pts.size(); ++k) {
      radii.push_back(cfg.radius_min_m == cfg.radius_max_m ? cfg.radius_max_m : draw(rng));
      vel.push_back(to_vec<D>(pc.initial.velocity_m_s));
    }
  }
  if (!pc.carving.empty() && !grains) {
    // Leave the carved parts' regions empty (a charge, a plate inside the soil box); a packing
    // did so itself (and its settled grains may rest on them, a little overlapped).
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
  // Zones set the velocity of the grains whose centres lie in them (later zones win); not
  // while settling: a settled bed starts from rest, then takes them.
  for (const parts::Zone& z : pc.zones)
    for (std::size_t k = 0; k < pts.size() && z.velocity_m_s && !settling; ++k)
      if (parts::region_contains<D>(z.region, pts[k])) vel[k] = to_vec<D>(*z.velocity_m_s);
  if (settings.packing.agitation_m_s > 0 && !settling) {  // not while settling
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
  return out;
}

// The mass of a grain of radius r: 2D disks per metre of depth, 3D spheres.
template <int D>
Real grain_mass(Real rho, Real r) {
  return D == 2 ? rho * std::numbers::pi * r * r : rho * 4.0 / 3.0 * std::numbers::pi * r * r * r;
}

}  // namespace

template <int D>
DemPart<D>::DemPart(const PartSettings& settings, const std::vector<Grain<D>>* grains,
                    std::optional<Real> local_damping)
    : name_(settings.part.name),
      where_(settings.part.where),
      cfg_(settings.dem),
      gravity_(to_vec<D>(settings.part.domain.gravity_m_s2)),
      domain_lo_(to_vec<D>(settings.part.domain.min_m)),
      domain_hi_(to_vec<D>(settings.part.domain.max_m)),
      // A settling part keeps every grain: one that leaves fails the settling (and its
      // absorbing faces are rigid).
      leave_domain_(settings.part.domain.outflow == parts::Outflow::Remove && !local_damping),
      outflow_remove_(leave_domain_ || (!settings.dem.absorbing_walls.empty() && !local_damping)),
      outflow_batch_steps_(static_cast<Index>(settings.part.domain.outflow_batch_steps)),
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
      surface_overlap_(f_.add_scalar("coupling_surface_overlap", "m", kRestart)),
      stress_(f_.add_tensor(kStressField, "Pa", kOutput)),
      work_external_(f_.add_scalar("work_external", "J", kRestart)),
      work_contact_(f_.add_scalar("work_contact", "J", kRestart)),
      work_damping_(f_.add_scalar("work_damping", "J", kRestart)),
      reflections_(f_.add_scalar("wall_reflections", "1", kRestart)) {
  symmetry_ = settings.part.domain.symmetry_planes;
  init_laws(settings);
  if (local_damping) {
    cfg_.local_damping = *local_damping;
    // While settling, absorbing faces are rigid walls: the bed settles on them, and the
    // run then holds the reactions they end with (absorbing_wall.hpp).
    cfg_.walls.insert(cfg_.walls.end(), cfg_.absorbing_walls.begin(), cfg_.absorbing_walls.end());
    cfg_.absorbing_walls.clear();
  }
  const InitialGrains<D> start = initial_grains<D>(settings, grains, local_damping.has_value());
  place_grains(start.pts, start.radii, start.vel);
  add_bed_measures(settings);
  // While settling, the parts this one is carved around (a charge, a plate) are fixed bodies
  // the grains rest on; in the run those parts' own contacts take over.
  if (local_damping) bodies_ = settings.part.carving;
  init_walls(local_damping.has_value());
  // A settling part (local damping overridden) carries no bonds: they are made at t = 0 of
  // the run, between the settled grains.
  if (cfg_.bonds.enabled && !local_damping) make_bonds();
  if (!cfg_.absorbing_walls.empty()) init_absorbing_walls(settings);
}

// The bed's solid fraction, the grains' volume over the region's less what the parts it is
// carved around take (parts::carved_volume: a box region), and its bulk density, the grains'
// density times that fraction (summary.json, crater check).
template <int D>
void DemPart<D>::add_bed_measures(const PartSettings& settings) {
  const Real free = parts::bed_volume<D>(settings.part);
  if (!(free > 0)) return;
  const Real solid =
      parallel::deterministic_sum<Real>(f_.size(), [&](Index i) { return grain_volume<D>(r_[i]); });
  solid_fraction_ = solid / free;
  add_diagnostic("solid_fraction", solid_fraction_);
  add_diagnostic("bulk_density_kg_m3", settings.rho0_kg_m3 * solid / free);
}

// The contact law (the registry, contact_laws.hpp) and the models beside it.
template <int D>
void DemPart<D>::init_laws(const PartSettings& settings) {
  const GranularMaterial& mat = settings.grain;
  rho_ = settings.rho0_kg_m3;
  grain_ = mat;
  laws_ = ContactLawRegistry::make(cfg_, mat);
  rows_ =
      D == 2 &&
      std::visit([&]<class Law>(const LawPair<Law>& /*laws*/) { return Law::row_of_spheres(cfg_); },
                 laws_);
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
}

// The grains' fields from their centres, radii and velocities, and their empty contact
// histories.
template <int D>
void DemPart<D>::place_grains(const std::vector<Vec<D>>& pts, const std::vector<Real>& radii,
                              const std::vector<Vec<D>>& vel) {
  const Index n = static_cast<Index>(pts.size());
  f_.resize(n);
  std::fill(surface_offset_.begin(), surface_offset_.end(), Real(-1));  // not touching
  r_min_ = std::numeric_limits<Real>::infinity();
  step_at_ = -1;
  for (Index i = 0; i < n; ++i) {
    const Real r = radii[static_cast<std::size_t>(i)];
    id_[i] = i;
    x_[i] = pts[static_cast<std::size_t>(i)];
    v_[i] = vel[static_cast<std::size_t>(i)];
    r_[i] = r;
    // 2D: disks per metre of depth, I = m r^2 / 2; 3D: spheres, I = 2 m r^2 / 5.
    m_[i] = grain_mass<D>(rho_, r);
    inertia_[i] = (D == 2 ? 0.5 : 0.4) * m_[i] * r * r;
    r_min_ = std::min(r_min_, r);
    r_max_ = std::max(r_max_, r);
  }
  partner_.assign(static_cast<std::size_t>(n) * kMaxContacts, kNoContact);
  xi_.assign(static_cast<std::size_t>(n) * kMaxContacts, Vec<D>::Zero());
  if (rolling_.friction > 0)
    roll_.assign(static_cast<std::size_t>(n) * kMaxContacts, angular_zero<D>());
}

template <int D>
parts::StableStep DemPart<D>::stable_step() const {
  // On one rank the limit changes only with the grains (load_state, remove_outflow): kept.
  if (!comm_ && step_at_ == f_.size()) return step_;
  parts::StableStep s;
  // The smallest grain of smallest id (r_min_ is the whole bed's, on every rank): the same
  // entity named on any rank count.
  std::int64_t smallest = std::numeric_limits<std::int64_t>::max();
  for (Index i = 0; i < f_.size(); ++i)
    if (r_[i] == r_min_ && !ghost(i)) smallest = std::min(smallest, id_[i]);
  // The law's own step (Hertz-Mindlin: the Rayleigh step) and its springs' stiffness.
  const LawStep law = std::visit(
      [&]<class Law>(const LawPair<Law>& /*laws*/) {
        return Law::part_step(LawStepQuery{
            .dem = cfg_, .grain = grain_, .radius_min_m = r_min_, .density_kg_m3 = rho_});
      },
      laws_);
  s.dt_s = law.dt_s;
  s.reason = law.reason;
  // Linear springs and bonds: f sqrt(m_min / k_max) (O'Sullivan & Bray 2004: 0.17 covers the
  // rotational modes and several contacts per grain; 2 sqrt(m/k) is the bare oscillator's
  // limit). Bonds act in parallel with the contact, so their stiffness adds.
  Real k = 0;
  k += law.stiffness_n_m;
  if (cfg_.bonds.enabled)
    k += std::max(bond_law_.normal_stiffness_pa_m, bond_law_.shear_stiffness_pa_m) *
         bond_section<D>(cfg_.bonds.radius_multiplier * r_max_).area;
  if (k > 0) {
    const Real m_min = grain_mass<D>(rho_, r_min_);
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
    const Real m_min = grain_mass<D>(rho_, r_min_);
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
  if (comm_) smallest = comm_->min_with_id({s.dt_s, smallest}).id;
  if (smallest != std::numeric_limits<std::int64_t>::max()) s.entity_id = smallest;
  if (!comm_) {
    step_ = s;
    step_at_ = f_.size();
  }
  return s;
}

// Forces of contacts with other parts join force_ and torque_ after the grains' own (local
// damping acts on the grains' own unbalanced force only).
template <int D>
void DemPart<D>::add_contact_forces(const std::vector<Vec<D>>& force,
                                    const std::vector<AngularVec<D>>& torque) {
  expect_grain_count(force, torque);
  held_known_ = false;
  // One pass: the power of the contact forces over the advance just taken (the old forces and
  // these, ContactWork::settle), then the new forces in.
  const bool booking = contact_.begin(f_.size());
  const Real half_dt = contact_.half_dt();
  std::vector<Real>& power = contact_.powers();
  parallel::for_each(f_.size(), [&](Index i) {
    take_contact_force(i, force[at(i)], torque[at(i)], booking, half_dt, power);
  });
  contact_.book(comm_ ? *comm_ : parallel::Comm{}, f_.size());
}

template <int D>
void DemPart<D>::add_touched_contact_forces(const std::vector<Vec<D>>& force,
                                            const std::vector<AngularVec<D>>& torque,
                                            std::span<const Index> touched) {
  // Only the grains the new forces touch and those the old ones touched can change: the others
  // have zero forces before and after, and their power is zero. Unless the grains moved in
  // their arrays since the last call (a re-sort, an outflow, a load, a migration or new
  // ghosts), which the full pass takes. On ranks the work is booked over the ranks as the
  // full pass books it (a ghost's power is zero).
  if (!held_known_ || held_epoch_ != f_.layout_epoch()) {
    add_contact_forces(force, torque);
  } else {
    expect_grain_count(force, torque);
    visit_.clear();
    std::set_union(held_.begin(), held_.end(), touched.begin(), touched.end(),
                   std::back_inserter(visit_));
    const bool booking = contact_.begin(f_.size());
    const Real half_dt = contact_.half_dt();
    std::vector<Real>& power = contact_.powers();
    parallel::for_each(static_cast<Index>(visit_.size()), [&](Index q) {
      const Index i = visit_[at(q)];
      take_contact_force(i, force[at(i)], torque[at(i)], booking, half_dt, power);
    });
    contact_.book_set(comm_ ? *comm_ : parallel::Comm{}, visit_);
  }
  held_.assign(touched.begin(), touched.end());
  held_epoch_ = f_.layout_epoch();
  held_known_ = true;
}

template <int D>
void DemPart<D>::advance(Real t, Real dt) {
  const Real half = 0.5 * dt;
  contact_.moved(dt);
  next_contact_.started();
  move_walls(t, dt);  // the planes of t + dt, before the grains meet them
  // One pass: kick, drift, the wall guard (reflect), the work of gravity at the new
  // velocities (before any reflection) and the largest squared displacement since the list
  // was built, which update_neighbors then needs not measure again.
  struct Pass {
    Real moved_sq = 0;
    Pass& operator+=(const Pass& o) {
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
    if (ghost(i)) return p;  // its owner's to move (refresh_ghosts)
    v_[i] += (half / m_[i]) * force_[i];
    w_[i] += (half / inertia_[i]) * torque_[i];
    x_[i] += dt * v_[i];
    if (gravity) work_external_[i] += dt * (m_[i] * gravity_.dot(v_[i]));
    if (guard && !inside_guard(i)) reflect_at_walls(i, reflections_[i], work_contact_[i]);
    if (measure) p.moved_sq = (x_[i] - built[static_cast<std::size_t>(i)]).squaredNorm();
    return p;
  });
  moved_sq_ = measure ? sum.moved_sq : -1;
}

template <int D>
void DemPart<D>::finish_step(Real dt) {
  const Real half = 0.5 * dt;
  parallel::for_each(f_.size(), [&](Index i) {
    if (ghost(i)) return;
    v_[i] += (half / m_[i]) * force_[i];
    w_[i] += (half / inertia_[i]) * torque_[i];
  });
  next_contact_.finished([&](const auto& f, const auto& t) { take_contact(f, t); });
  if (outflow_remove_) remove_outflow();
}

#define CRATER_DEM_PART(D)                                                                    \
  template void DemPart<D>::add_bed_measures(const PartSettings&);                            \
  template DemPart<D>::DemPart(const PartSettings&, const std::vector<Grain<D>>*,             \
                               std::optional<Real>);                                          \
  template parts::StableStep DemPart<D>::stable_step() const;                                 \
  template void DemPart<D>::add_contact_forces(const std::vector<Vec<D>>&,                    \
                                               const std::vector<AngularVec<D>>&);            \
  template void DemPart<D>::add_touched_contact_forces(                                       \
      const std::vector<Vec<D>>&, const std::vector<AngularVec<D>>&, std::span<const Index>); \
  template void DemPart<D>::advance(Real, Real);                                              \
  template void DemPart<D>::finish_step(Real);
CRATER_DEM_PART(2)
CRATER_DEM_PART(3)
#undef CRATER_DEM_PART

}  // namespace detail

template <int D>
std::unique_ptr<parts::Part<D>> make_dem_part(const PartSettings& settings,
                                              const std::vector<Grain<D>>* grains,
                                              const PackingReport& report,
                                              const ContactHistory<D>* contacts) {
  using detail::DemPart;
  if (!grains) return std::make_unique<DemPart<D>>(settings);
  const parts::PartSetup& part = settings.part;
  auto p = std::make_unique<DemPart<D>>(settings, grains);
  if (contacts) p->start_from(*contacts);
  // Porosity of the packed grains over the region's cross-section times the bed's height
  // (box regions; along gravity) less the carved bodies, and how the packing was obtained.
  if (part.region.type == parts::RegionType::Box && !grains->empty()) {
    const Vec<D> g = parts::to_vec<D>(part.domain.gravity_m_s2);
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
    // The bodies the bed is carved around are not pore space (as parts::bed_volume).
    const Real carved = parts::carved_volume<D>(part.region, part.carving);
    p->add_diagnostic("packing_porosity", 1 - solid / (area * (top - bottom) - carved));
    p->add_diagnostic("packing_bed_height_m", top - bottom);
  }
  if (settings.packing.settle) {
    p->add_diagnostic("packing_reused", report.reused ? 1.0 : 0.0);
    if (report.unsettled) {
      p->add_diagnostic("packing_unsettled", 1.0);
    } else if (!report.reused) {
      p->add_diagnostic("settle_time_s", report.settle_time_s);
      p->add_diagnostic("settle_steps", static_cast<Real>(report.settle_steps));
    }
  }
  return p;
}

template std::unique_ptr<parts::Part<2>> make_dem_part<2>(const PartSettings&,
                                                          const std::vector<Grain<2>>*,
                                                          const PackingReport&,
                                                          const ContactHistory<2>*);
template std::unique_ptr<parts::Part<3>> make_dem_part<3>(const PartSettings&,
                                                          const std::vector<Grain<3>>*,
                                                          const PackingReport&,
                                                          const ContactHistory<3>*);

}  // namespace crater::dem
