// SPH equations as implemented (docs/theory.md has them with the paper's numbers). With the
// particle volume V_j = m_j / rho_j (the multiphase form of Colagrossi & Landrini 2003, J.
// Comput. Phys. 191, 448, which stays well behaved across density jumps such as a shock
// tube's contact or a charge's edge; for uniform mass it is the paper's eqs. 32 and 34):
//   continuity (32):  d rho_i/dt = rho_i sum_j V_j v_ij . grad_i W_ij
//   momentum (34):    d v_i/dt   = -1/rho_i sum_j V_j (p_i + p_j) grad_i W_ij
//                                  - sum_j m_j (Pi_ij + R_ij f_ij^4) grad_i W_ij
//                                  + (viscous term, eq. 36) + g
//   energy:           d e_i/dt   = p_i/rho_i sum_j V_j v_ij . grad_i W_ij
//                                  + 1/2 sum_j m_j Pi_ij v_ij . grad_i W_ij + viscous heating
//   Monaghan viscosity: Pi_ij = (-alpha cbar mu + beta mu^2) / rhobar for v_ij . r_ij < 0,
//                       mu = hbar v_ij . r_ij / (r_ij^2 + 0.01 hbar^2)
// Pairs use hbar = (h_i + h_j)/2, so grad_i W_ij = -grad_j W_ji and pair forces are equal and
// opposite: momentum is conserved to round-off; kinetic + internal energy is conserved by the
// semi-discrete equations (the energy equation is the one that balances the momentum
// equation's pressure work pair by pair), and by the wall terms (see `pair` in rates()).
// Each particle gathers over its own neighbour list (ascending j), so the sums are evaluated in
// the same order for any number of threads (bit-identical results).
#include "sph/sph_part.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>
#include <array>
#include <cmath>
#include <limits>

#include "fields/field_set.hpp"
#include "materials/eos/eos.hpp"
#include "neighbors/cell_grid.hpp"
#include "neighbors/neighbor_list.hpp"
#include "neighbors/verlet_skin.hpp"
#include "parallel/parallel.hpp"
#include "parts/region.hpp"
#include "sph/kernels.hpp"

namespace crater::sph {
namespace {

using fields::kHalo;
using fields::kNone;
using fields::kOutput;
using fields::kRestart;
using fields::kStateRoles;

constexpr Real kSkin = 0.25;  // neighbour-list margin, as a fraction of the largest support
constexpr Real kInf = std::numeric_limits<Real>::infinity();

using parts::to_vec;

/// Dummy wall particles behind the walled faces of the domain box, `layers` deep at pitch s
/// (Adami, Hu & Adams 2012, J. Comput. Phys. 231, 7057). A corner shared by faces of axes
/// a < b is laid by the face of axis a only (when both are walled), so no point is doubled.
template <int D>
struct WallLattice {
  std::vector<Vec<D>> x;
  // Per wall particle: -1 along each axis where it lies beyond a face of the domain, +1
  // elsewhere; a free-slip wall mirrors those velocity components (both at a corner).
  std::vector<Vec<D>> mirror;
};

template <int D>
WallLattice<D> wall_lattice(const parts::Domain& domain, const std::vector<parts::Face>& faces,
                            int layers, Real s) {
  const Vec<D> lo = to_vec<D>(domain.min_m), hi = to_vec<D>(domain.max_m);
  auto walled = [&](int axis, int side) {
    for (auto f : faces)
      if (static_cast<int>(f) == 2 * axis + side) return true;
    return false;
  };
  // Coordinates along an axis: inside [lo, hi] at lo + (i + 1/2) s; beyond a face at
  // face -/+ (k + 1/2) s.
  auto coords = [&](int axis, bool extend) {
    std::vector<Real> v;
    const auto n = static_cast<Index>(std::llround((hi[axis] - lo[axis]) / s));
    if (extend && walled(axis, 0))
      for (int k = layers - 1; k >= 0; --k)
        v.push_back(lo[axis] - (k + 0.5) * s);
    for (Index i = 0; i < n; ++i)
      v.push_back(lo[axis] + (static_cast<Real>(i) + 0.5) * s);
    if (extend && walled(axis, 1))
      for (int k = 0; k < layers; ++k)
        v.push_back(hi[axis] + (k + 0.5) * s);
    return v;
  };
  WallLattice<D> out;
  for (int a = 0; a < D; ++a)
    for (int side = 0; side < 2; ++side) {
      if (!walled(a, side)) continue;
      std::vector<std::vector<Real>> axes(D);
      for (int d = 0; d < D; ++d) {
        if (d == a) {
          for (int k = 0; k < layers; ++k)
            axes[d].push_back(side == 0 ? lo[a] - (k + 0.5) * s : hi[a] + (k + 0.5) * s);
        } else {
          axes[d] = coords(d, d > a);
        }
      }
      std::vector<std::size_t> i(D, 0);
      while (true) {
        Vec<D> x;
        Vec<D> mirror;
        for (int d = 0; d < D; ++d) {
          x[d] = axes[d][i[d]];
          mirror[d] = (x[d] < lo[d] || x[d] > hi[d]) ? -1.0 : 1.0;
        }
        out.x.push_back(x);
        out.mirror.push_back(mirror);
        int d = 0;
        while (d < D && ++i[d] == axes[d].size())
          i[d++] = 0;
        if (d == D) break;
      }
    }
  return out;
}

template <int D>
class SphPart final : public parts::Part<D> {
 public:
  explicit SphPart(const PartSettings& settings)
      : name_(settings.part.name),
        eos_(settings.eos),
        cfg_(settings.sph),
        spacing_(settings.part.spacing_m),
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
        burn_(f_.add_scalar("burn_fraction", "1", kOutput | kRestart)),
        light_(f_.add_scalar("lighting_time", "s", kRestart | kHalo)),
        a_(f_.add_vector("acceleration", "m/s^2", kRestart)),
        drho_(f_.add_scalar("density_rate", "kg/m^3/s", kRestart)),
        de_(f_.add_scalar("energy_rate", "W/kg", kRestart)),
        dx_xsph_(f_.add_vector("xsph_velocity", "m/s", kRestart)),
        vh_(f_.add_vector("velocity_half", "m/s", kNone)),
        rhoh_(f_.add_scalar("density_half", "kg/m^3", kNone)),
        eh_(f_.add_scalar("energy_half", "J/kg", kNone)),
        dt_cv_(f_.add_scalar("dt_signal", "s", kNone)),
        fc_(f_.add_vector("contact_force", "N", kRestart)),
        surface_offset_(f_.add_scalar("contact_surface_offset", "m", kRestart)),
        surface_overlap_(f_.add_scalar("contact_surface_overlap", "m", kRestart)) {
    const parts::PartSetup& pc = settings.part;
    // Particles: the part's lattice, except where a zone with its own spacing lays its own
    // (equal-mass particles across a density jump, as a shock tube wants); each particle
    // remembers its lattice pitch.
    std::vector<Vec<D>> pts;
    std::vector<Real> pitch;
    auto owner = [&](const Vec<D>& x) {  // index of the last spacing zone holding x, or -1
      int k = -1;
      for (std::size_t z = 0; z < pc.zones.size(); ++z)
        if (pc.zones[z].spacing_m && parts::region_contains<D>(pc.zones[z].region, x))
          k = static_cast<int>(z);
      return k;
    };
    for (const auto& x : parts::region_lattice<D>(pc.region, spacing_))
      if (owner(x) < 0 && !parts::carved<D>(pc.carving, x, 0.5 * spacing_))
        pts.push_back(x), pitch.push_back(spacing_);
    for (std::size_t z = 0; z < pc.zones.size(); ++z) {
      if (!pc.zones[z].spacing_m) continue;
      for (const auto& x : parts::region_lattice<D>(pc.zones[z].region, *pc.zones[z].spacing_m))
        if (parts::region_contains<D>(pc.region, x) && owner(x) == static_cast<int>(z))
          pts.push_back(x), pitch.push_back(*pc.zones[z].spacing_m);
    }
    const Index n = static_cast<Index>(pts.size());
    f_.resize(n);
    std::fill(surface_offset_.begin(), surface_offset_.end(), Real(-1));  // not touching
    cell_volume_ = std::pow(spacing_, D);
    h0_ = cfg_.h_factor * spacing_;
    if (const auto* jwl = std::get_if<materials::JwlParams>(&eos_)) {
      detonation_velocity_ = jwl->d_cj_m_s;
      is_explosive_ = true;
      rho_ref_ = jwl->rho0_kg_m3;
      rho_cj_ = materials::jwl_cj_state(*jwl).density_kg_m3;
      beta_burn_ = std::isfinite(rho_cj_) && rho_cj_ > rho_ref_ && !pc.detonations.empty();
      burn_width_ = 1.5 * spacing_;
    }

    for (Index i = 0; i < n; ++i) {
      // The part's initial state, then the last zone containing the particle.
      Real rho = pc.initial.density_kg_m3.value_or(settings.rho0_kg_m3);
      std::optional<Real> pressure = pc.initial.pressure_pa;
      Vec<D> vel = to_vec<D>(pc.initial.velocity_m_s);
      for (const auto& z : pc.zones) {
        if (!parts::region_contains<D>(z.region, pts[i])) continue;
        if (z.density_kg_m3) rho = *z.density_kg_m3;
        if (z.pressure_pa) pressure = z.pressure_pa;
        if (z.velocity_m_s) vel = to_vec<D>(*z.velocity_m_s);
      }
      id_[i] = i;
      x_[i] = pts[i];
      v_[i] = vel;
      m_[i] = rho * std::pow(pitch[i], D);
      rho_[i] = rho;
      h_[i] = cfg_.h_factor * pitch[i];
      e_[i] = initial_energy(rho, pressure);
      // Programmed burn: a particle lights when the detonation front, running at D from the
      // nearest detonation point, reaches it. No points: all lit at t = 0.
      Real tl = is_explosive_ && !pc.detonations.empty() ? kInf : 0;
      for (const auto& dp : pc.detonations)
        tl = std::min(tl,
                      dp.time_s + (pts[i] - to_vec<D>(dp.point_m)).norm() / detonation_velocity_);
      light_[i] = tl;
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
    wall_p_.assign(nw, 0);
    wall_rho_.assign(nw, settings.rho0_kg_m3);
    wall_c_.assign(nw, 0);
    wall_v_.assign(nw, Vec<D>::Zero());
    resort();
  }

  const std::string& name() const override { return name_; }
  const char* method() const override { return "sph"; }
  Index count() const override { return f_.size(); }
  Real mass_kg() const override {
    return parallel::deterministic_sum<Real>(f_.size(), [&](Index i) { return m_[i]; });
  }

  parts::StableStep stable_step() const override {
    // Monaghan & Kos (1999): dt = cfl * min(dt_f, dt_cv), dt_f = sqrt(h/|a|),
    // dt_cv = h / (c + max_j |mu_ij|) (max over neighbours, from the force loop).
    parts::StableStep s;
    s.dt_s = kInf;
    for (Index i = 0; i < f_.size(); ++i) {
      const Real an = a_[i].norm();
      const Real dt_f = an > 0 ? std::sqrt(h_[i] / an) : kInf;
      const Real dt_i = cfg_.cfl * std::min(dt_f, dt_cv_[i]);
      if (dt_i < s.dt_s) {
        s.dt_s = dt_i;
        s.entity_id = id_[i];
        s.reason = dt_f < dt_cv_[i]
                       ? fmt::format("force criterion, |a| = {:.3g} m/s^2", an)
                       : fmt::format("CFL {} with sound speed {:.4g} m/s", cfg_.cfl, c_[i]);
      }
    }
    return s;
  }

  void compute_forces(Real t) override {
    time_s_ = t;
    update_smoothing_lengths();
    update_neighbors();
    update_eos(t);
    pair_rates();
  }

  std::optional<parts::Fault> check() const override {
    const Index n = f_.size();
    // First offending particle in index order (deterministic).
    Index bad = n;
#pragma omp parallel for schedule(static) reduction(min : bad) if (n >= parallel::parallel_min())
    for (Index i = 0; i < n; ++i)
      if (!healthy(i)) bad = std::min(bad, i);
    if (bad == n) return std::nullopt;
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
    return parts::Fault{id_[i], what};
  }

  // Velocity Verlet with predicted rates: density and energy are kicked like the velocity, so
  // the state of time t+dt (x, v, rho, e) is second-order accurate, and the forces at t+dt are
  // evaluated with predicted v, rho, e of that time (Springel 2005 uses the same prediction).
  void advance(Real /*t*/, Real dt) override {
    const Real half = 0.5 * dt;
    parallel::for_each(f_.size(), [&](Index i) {
      vh_[i] = v_[i] + half * a_[i];
      rhoh_[i] = rho_[i] + half * drho_[i];
      eh_[i] = e_[i] + half * de_[i];
      x_[i] += dt * (vh_[i] + dx_xsph_[i]);
      if (has_walls_) reflect_at_walls(i);
      v_[i] = vh_[i] + half * a_[i];
      rho_[i] = rhoh_[i] + half * drho_[i];
      e_[i] = eh_[i] + half * de_[i];
    });
    last_dt_ = dt;
    contact_pending_ = true;
    // Work of gravity over the step, with the mid-step velocity.
    if (gravity_.squaredNorm() > 0)
      external_work_ += dt * parallel::deterministic_sum<Real>(
                                 f_.size(), [&](Index i) { return m_[i] * gravity_.dot(vh_[i]); });
  }

  void finish_step(Real dt) override {
    const Real half = 0.5 * dt;
    parallel::for_each(f_.size(), [&](Index i) {
      v_[i] = vh_[i] + half * a_[i];
      rho_[i] = rhoh_[i] + half * drho_[i];
      e_[i] = eh_[i] + half * de_[i];
    });
    if (outflow_remove_) remove_outflow();
  }

  /// Particles as contacts see them: spheres (disks) of half their volume-equivalent size,
  /// (m / rho)^(1/D) / 2, moving at the predicted velocity.
  std::optional<parts::ContactPoints<D>> contact_points() const override {
    contact_radius_.resize(static_cast<std::size_t>(f_.size()));
    parallel::for_each(
        f_.size(), [&](Index i) { contact_radius_[i] = Real(0.5) * dth_root<D>(m_[i] / rho_[i]); });
    parts::ContactPoints<D> p;
    p.position = &x_;
    p.velocity = &v_;
    p.mass = &m_;
    p.radius = &contact_radius_;
    p.surface_offset = &surface_offset_;
    p.surface_overlap = &surface_overlap_;
    return p;
  }

  void add_contact_forces(const std::vector<Vec<D>>& force,
                          const std::vector<AxialVec<D>>& /*torque*/) override {
    if (static_cast<Index>(force.size()) != f_.size())
      throw std::logic_error("sph: contact forces for another particle count");
    if (contact_pending_ && last_dt_ > 0) {
      const Real half_dt = Real(0.5) * last_dt_;
      contact_work_ += parallel::deterministic_sum<Real>(
          f_.size(), [&](Index i) { return half_dt * vh_[i].dot(fc_[i] + force[i]); });
    }
    contact_pending_ = false;
    parallel::for_each(f_.size(), [&](Index i) {
      fc_[i] = force[i];
      a_[i] += fc_[i] / m_[i];
    });
  }

  parts::Energies energies() const override {
    struct KU {
      Real k = 0, u = 0;
      KU& operator+=(const KU& o) {
        k += o.k;
        u += o.u;
        return *this;
      }
    };
    const KU s = parallel::deterministic_sum<KU>(f_.size(), [&](Index i) {
      return KU{0.5 * m_[i] * v_[i].squaredNorm(), m_[i] * e_[i]};
    });
    parts::Energies en;
    en.kinetic_j = s.k;
    en.internal_j = s.u;
    en.external_work_j = external_work_;
    en.contact_j = -contact_work_;
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
    std::vector<parts::Diagnostic> d;
    if (has_walls_) {
      d.push_back({"wall_reflections", static_cast<Real>(reflections_)});
      d.push_back({"wall_max_penetration_m", max_penetration_});
    }
    if (outflow_remove_) {
      d.push_back({"left_domain_count", static_cast<Real>(left_count_)});
      d.push_back({"left_domain_mass_kg", left_mass_kg_});
      d.push_back({"left_domain_energy_j", left_energy_j_});
    }
    return d;
  }

 private:
  Real initial_energy(Real rho, std::optional<Real> pressure) const {
    if (const auto* jwl = std::get_if<materials::JwlParams>(&eos_))
      return jwl->e0_j_m3 / jwl->rho0_kg_m3;  // chemical energy, released by the burn
    if (const auto* gas = std::get_if<materials::IdealGasParams>(&eos_))
      return pressure.value_or(0.0) / ((gas->gamma - 1) * rho);
    return 0;  // Tait: pressure follows from density alone
  }

  // A particle that crosses a walled face in a step is put back by specular reflection (its
  // normal velocity reversed): at a free-slip wall this is the symmetry condition itself (the
  // particle and its image trade places); at a no-slip wall it is a safeguard behind the
  // dummy particles' pressure. Reflection conserves kinetic energy; the wall takes the
  // momentum. Counted in summary.json: `wall_reflections` and `wall_max_penetration_m`, the
  // deepest crossing (a particle sliding on a free-slip floor at a free surface, where the
  // pressure is about zero, can dip below it by round-off-sized amounts: the image's push
  // vanishes as the kernel gradient does at r = 0).
  void reflect_at_walls(Index i) {
    for (const parts::Face f : cfg_.walls) {
      const int axis = static_cast<int>(f) / 2;
      const bool low = static_cast<int>(f) % 2 == 0;
      const Real face = low ? domain_lo_[axis] : domain_hi_[axis];
      const Real depth = low ? face - x_[i][axis] : x_[i][axis] - face;
      if (depth > 0) {
        x_[i][axis] = low ? face + depth : face - depth;
        vh_[i][axis] = -vh_[i][axis];
        a_[i][axis] = -a_[i][axis];
#pragma omp critical(crater_sph_reflections)
        {
          ++reflections_;
          max_penetration_ = std::max(max_penetration_, depth);
        }
      }
    }
  }

  bool in_domain(Index i) const {
    for (int d = 0; d < D; ++d)
      if (!(x_[i][d] >= domain_lo_[d] && x_[i][d] <= domain_hi_[d])) return false;
    return true;
  }
  bool healthy(Index i) const {
    return std::isfinite(drho_[i]) && std::isfinite(de_[i]) && a_[i].allFinite() && rho_[i] > 0 &&
           std::isfinite(p_[i]) && (outflow_remove_ ? x_[i].allFinite() : in_domain(i));
  }

  // outflow = "remove": particles beyond the domain box leave the model at the end of the step,
  // with the velocity, density and energy of t + dt, as hydrocodes deactivate material that
  // leaves the mesh. Their kinetic and internal energy goes to eroded_j, so the balance still
  // closes. The rest keep their order (compaction in index order): the same numbers for any
  // thread count, and after a restart from this state (which holds the rebuilt lists' skin).
  void remove_outflow() {
    const Index n = f_.size();
    keep_.resize(static_cast<std::size_t>(n));
    struct Left {
      Index count = 0;
      Real mass = 0, energy = 0;
      Left& operator+=(const Left& o) {
        count += o.count;
        mass += o.mass;
        energy += o.energy;
        return *this;
      }
    };
    const Left left = parallel::deterministic_sum<Left>(n, [&](Index i) {
      keep_[static_cast<std::size_t>(i)] = in_domain(i);
      if (keep_[static_cast<std::size_t>(i)]) return Left{};
      return Left{1, m_[i], 0.5 * m_[i] * v_[i].squaredNorm() + m_[i] * e_[i]};
    });
    if (left.count == 0) return;
    if (left_count_ == 0)
      spdlog::info(
          "part '{}': particles leave the domain from t = {:.6g} s on and are removed "
          "(domain.outflow = \"remove\"; left_domain_* in summary.json)",
          name_, time_s_);
    left_count_ += left.count;
    left_mass_kg_ += left.mass;
    left_energy_j_ += left.energy;
    f_.compact(keep_);
    // The rates of the state without them (lists rebuilt for the remaining particles, in their
    // order; pressures and sound speeds are the particles' own), the contact forces added as in
    // add_contact_forces: the next half kick then owes nothing to a removed particle, and the
    // pair terms stay equal and opposite (kinetic + internal energy conserved). Without this,
    // their pressure work over that half kick (first order in dt) went unbooked: 1 % of the
    // energy of the gas disk of tests/verification/outflow. Costs one more evaluation of the
    // rates in the steps where particles leave.
    skin_.built(std::span<const Vec<D>>(x_), WendlandC2<D>::support * h_max_);
    build_lists();
    pair_rates();
    parallel::for_each(f_.size(), [&](Index i) { a_[i] += fc_[i] / m_[i]; });
  }

  // Neighbour lists with a skin (Verlet 1967): built for the radius (1 + kSkin) x the largest
  // kernel support and kept while no particle has moved more than half the margin beyond what
  // the current supports need. Particles are re-sorted by cell at each rebuild (locality).
  // The pair loops test the true support, so a longer list only costs rejected candidates.
  void update_neighbors() {
    const Real need = WendlandC2<D>::support * h_max_;
    if (!skin_.stale(std::span<const Vec<D>>(x_), need)) return;
    resort();
    skin_.built(std::span<const Vec<D>>(x_), need);
    build_lists();
  }

  // The lists for the positions of the last rebuild (the current ones right after it; the
  // saved ones after a restart, which rebuilds the very same lists).
  void build_lists() {
    const std::span<const Vec<D>> xb = skin_.positions();
    const Real radius = skin_.radius();
    neighbors::build_neighbor_list<D>(xb, radius, neighbors::Pairs::Full, list_);
    if (!wall_x_.empty()) {
      neighbors::build_cross_list<D>(std::span<const Vec<D>>(wall_x_), xb, radius, wall_to_fluid_);
      neighbors::build_cross_list<D>(xb, std::span<const Vec<D>>(wall_x_), radius, fluid_to_wall_);
    }
    if (has_walls_ && !cfg_.wall_no_slip) {
      select_ghosts(xb, radius);
      ghost_positions(xb);
      neighbors::build_cross_list<D>(xb, std::span<const Vec<D>>(ghost_x_), radius,
                                     fluid_to_ghost_);
    }
  }

 public:
  void save_state(parts::StateWriter& w) const override {
    w.tag("sph");
    f_.save(w);
    w.value(h_max_);
    w.value(external_work_);
    w.value(contact_work_);
    w.value(last_dt_);
    w.value(contact_pending_);
    w.value(reflections_);
    w.value(max_penetration_);
    skin_.save(w);
    w.tag("outflow");
    w.value(left_count_);
    w.value(left_mass_kg_);
    w.value(left_energy_j_);
  }
  void load_state(parts::StateReader& r) override {
    r.tag("sph");
    f_.load(r);
    r.value(h_max_);
    r.value(external_work_);
    r.value(contact_work_);
    r.value(last_dt_);
    r.value(contact_pending_);
    r.value(reflections_);
    r.value(max_penetration_);
    skin_.load(r);
    r.tag("outflow");
    r.value(left_count_);
    r.value(left_mass_kg_);
    r.value(left_energy_j_);
    if (skin_.radius() > 0) build_lists();
  }

 private:
  // Free-slip walls are planes of symmetry: each particle within `radius` of a walled face has
  // a mirror image behind it (Libersky et al. 1993), with the parent's mass, density, smoothing
  // length and sound speed, its position and velocity reflected in the face, and its pressure
  // extended hydrostatically, p_g = p + rho g . (x_g - x). Near a corner the particle also has
  // the image in both faces. The images make the flow next to the wall that of the symmetric
  // problem: the continuity and pressure sums see a complete kernel, and the normal velocity
  // vanishes on the face. The image of particle j moves with j, so the images chosen at a list
  // rebuild serve until the next one (the parent must come within `radius` to interact).
  void select_ghosts(std::span<const Vec<D>> x, Real radius) {
    ghost_parent_.clear();
    ghost_sign_.clear();
    ghost_offset_.clear();
    const Index n = f_.size();
    for (Index j = 0; j < n; ++j) {
      // Per axis: no reflection (0), in the low face (1) or in the high face (2), if walled and
      // within reach.
      std::array<std::array<int, 3>, D> options{};
      std::array<int, D> count{};
      for (int a = 0; a < D; ++a) {
        options[a][count[a]++] = 0;
        for (const parts::Face f : cfg_.walls) {
          if (static_cast<int>(f) / 2 != a) continue;
          const bool low = static_cast<int>(f) % 2 == 0;
          const Vec<D>& xj = x[static_cast<std::size_t>(j)];
          const Real d = low ? xj[a] - domain_lo_[a] : domain_hi_[a] - xj[a];
          if (d < radius) options[a][count[a]++] = low ? 1 : 2;
        }
      }
      std::array<int, D> k{};
      while (true) {
        bool any = false;
        Vec<D> sign = Vec<D>::Ones(), offset = Vec<D>::Zero();
        for (int a = 0; a < D; ++a) {
          const int o = options[a][k[a]];
          if (o == 0) continue;
          any = true;
          sign[a] = -1;
          offset[a] = 2 * (o == 1 ? domain_lo_[a] : domain_hi_[a]);
        }
        if (any) {
          ghost_parent_.push_back(j);
          ghost_sign_.push_back(sign);
          ghost_offset_.push_back(offset);
        }
        int a = 0;
        while (a < D && ++k[a] == count[a])
          k[a++] = 0;
        if (a == D) break;
      }
    }
    ghost_x_.resize(ghost_parent_.size());
    ghost_v_.resize(ghost_parent_.size());
    ghost_p_.resize(ghost_parent_.size());
  }

  void ghost_positions(std::span<const Vec<D>> x) {
    parallel::for_each(static_cast<Index>(ghost_parent_.size()), [&](Index g) {
      ghost_x_[g] = ghost_offset_[g] +
                    ghost_sign_[g].cwiseProduct(x[static_cast<std::size_t>(ghost_parent_[g])]);
    });
  }

  void ghost_state() {
    if (ghost_parent_.empty()) return;
    ghost_positions(std::span<const Vec<D>>(x_));
    const Vec<D> g = gravity_;
    parallel::for_each(static_cast<Index>(ghost_parent_.size()), [&](Index k) {
      const Index j = ghost_parent_[k];
      ghost_v_[k] = ghost_sign_[k].cwiseProduct(v_[j]);
      ghost_p_[k] = p_[j] + rho_[j] * g.dot(ghost_x_[k] - x_[j]);
    });
  }

  // The wall and ghost states and the pair sums (rates) of the current state, on the current
  // lists.
  void pair_rates() {
    ghost_state();
    if (cfg_.kernel == KernelKind::WendlandC2) {
      wall_state<WendlandC2<D>>();
      rates<WendlandC2<D>>();
    } else {
      wall_state<CubicSpline<D>>();
      rates<CubicSpline<D>>();
    }
  }

  void resort() {
    const auto order =
        neighbors::cell_sort_order<D>(std::span<const Vec<D>>(x_), WendlandC2<D>::support * h_max_);
    f_.permute(order);
  }

  // Paper eq. 37, dh/dt = -(h / (D rho)) drho/dt, integrated exactly: h = h_factor (m/rho)^(1/D)
  // (= h_factor x spacing in the initial state).
  void update_smoothing_lengths() {
    if (!cfg_.variable_h) return;
    const Index n = f_.size();
    const Real hf = cfg_.h_factor;
    parallel::for_each(n, [&](Index i) {
      const Real volume = m_[i] / rho_[i];
      h_[i] = hf * (D == 2 ? std::sqrt(volume) : std::cbrt(volume));
    });
    h_max_ = std::max(h0_, parallel::max_over(n, 0.0, [&](Index i) { return h_[i]; }));
  }

  // Pressure and sound speed from the EOS, with the burn fraction F for explosives, as in the
  // programmed burn of Wilkins (1964) and LS-DYNA's *MAT_HIGH_EXPLOSIVE_BURN:
  //   F1 = (t - t_light) D / (1.5 dx)       (lighting time: the front reaches the particle)
  //   F2 = (1 - V) / (1 - V_CJ), V = rho0/rho (beta burn: compressed to the CJ volume, it burns)
  //   F  = min(1, max(F_previous, F1, F2)),  p = F p_JWL(rho, e).
  // F never decreases. F2 lets the products' compression light the explosive just ahead of the
  // front, which brings the front's pressure closer to P_CJ at a given resolution.
  void update_eos(Real t) {
    const Index n = f_.size();
    std::visit(
        [&](const auto& law) {
          parallel::for_each(n, [&](Index i) {
            Real burn = 1;
            if (is_explosive_) {
              const Real f1 =
                  t < light_[i] ? 0.0 : (t - light_[i]) * detonation_velocity_ / (burn_width_);
              const Real f2 =
                  beta_burn_ ? (1 - rho_ref_ / rho_[i]) / (1 - rho_ref_ / rho_cj_) : 0.0;
              burn = std::min(1.0, std::max({burn_[i], f1, f2}));
            }
            burn_[i] = burn;
            const Real p = materials::eos_pressure_of(law, rho_[i], e_[i]);
            p_[i] = burn * p;
            c_[i] = materials::eos_sound_speed_of(law, rho_[i], e_[i], p);
          });
        },
        eos_);
  }

  // Adami et al. (2012) eqs. 27-28: a wall particle's pressure is the kernel-weighted average of
  // its fluid neighbours' plus the hydrostatic part, p_w = (sum_f p_f W_wf + g . sum_f rho_f
  // r_wf W_wf) / sum_f W_wf (fixed walls: no wall acceleration); density and sound speed are
  // the same averages (Shepard); the velocity for the viscous terms is the averaged fluid
  // velocity mirrored in the wall (eq. 22 for no slip).
  template <class Kernel>
  void wall_state() {
    const auto nw = static_cast<Index>(wall_x_.size());
    if (nw == 0) return;
    const Vec<D> g = gravity_;
    parallel::for_each(nw, [&](Index w) {
      Real sw = 0, sp = 0, srho = 0, sc = 0;
      Vec<D> sv = Vec<D>::Zero(), srw = Vec<D>::Zero();
      for (const Index f : wall_to_fluid_.of(w)) {
        const Vec<D> rwf = wall_x_[w] - x_[f];
        const Real hbar = 0.5 * (h0_ + h_[f]);
        const Real wgt = Kernel::w(rwf.norm(), hbar);
        sw += wgt;
        sp += p_[f] * wgt;
        srho += rho_[f] * wgt;
        sc += c_[f] * wgt;
        sv += v_[f] * wgt;
        srw += rho_[f] * rwf * wgt;
      }
      if (sw > 0) {
        wall_p_[w] = (sp + g.dot(srw)) / sw;
        wall_rho_[w] = srho / sw;
        wall_c_[w] = sc / sw;
        // The velocity the viscous terms see: the fluid's, mirrored in the wall (no slip:
        // all of it, 2 v_wall - v; free slip: only its normal part, so sliding costs nothing).
        const Vec<D> vf = sv / sw;
        wall_v_[w] = cfg_.wall_no_slip ? Vec<D>(-vf) : Vec<D>(vf.cwiseProduct(wall_mirror_[w]));
      } else {
        wall_p_[w] = 0;
        wall_c_[w] = 0;
        wall_v_[w] = Vec<D>::Zero();
      }
    });
  }

  template <class Kernel>
  void rates() {
    const Index n = f_.size();
    const Real alpha = cfg_.av_alpha, beta = cfg_.av_beta;
    const Real mu_visc = cfg_.viscosity_pa_s;
    const Real eps_xsph = cfg_.xsph_epsilon;
    const Real eps_tensile = cfg_.tensile_epsilon;
    const Vec<D> g = gravity_;
    const bool walls = !wall_x_.empty();
    const bool ghosts = !ghost_parent_.empty();
    parallel::for_each(n, [&](Index i) {
      const Vec<D> xi = x_[i], vi = v_[i];
      const Real hi = h_[i], rhoi = rho_[i], ci = c_[i];
      const Real pi = p_[i];
      const Real inv_rhoi = 1 / rhoi;
      // Monaghan (2000) artificial pressure, only where the pressure is negative.
      const Real ri = pi < 0 ? eps_tensile * -pi / (rhoi * rhoi) : 0.0;
      Vec<D> acc = Vec<D>::Zero(), xsph = Vec<D>::Zero();
      Real drho = 0, de = 0, mu_max = 0;

      // One interaction with a neighbour of mass mj and volume vol_j = mj / rhoj. `wall` marks
      // a fixed wall particle: it cannot take its share of the pressure work, so particle i
      // books all of it, and kinetic plus internal energy stays conserved.
      auto pair = [&](const Vec<D>& rij, Real hj, Real mj, Real rhoj, Real pj, Real cj,
                      const Vec<D>& vj, const Vec<D>& vj_visc, bool wall)
          __attribute__((always_inline)) {
        const Real r2 = rij.squaredNorm();
        const Real hbar = 0.5 * (hi + hj);
        if (r2 >= Kernel::support * Kernel::support * hbar * hbar) return;
        const Real r = std::sqrt(r2);
        const Vec<D> gw = Kernel::grad_factor(r, hbar) * rij;
        const Vec<D> vij = vi - vj;
        const Vec<D> vij_visc = vi - vj_visc;
        const Real eta2 = 0.01 * hbar * hbar;
        const Real vdotr = vij_visc.dot(rij);
        const Real mu = hbar * vdotr / (r2 + eta2);
        mu_max = std::max(mu_max, std::abs(mu));
        Real visc = 0;
        if (vdotr < 0) {
          const Real cbar = 0.5 * (ci + cj);
          const Real rhobar = 0.5 * (rhoi + rhoj);
          visc = (-alpha * cbar * mu + beta * mu * mu) / rhobar;
        }
        Real tensile = 0;
        if (eps_tensile > 0) {
          const Real rj = pj < 0 ? eps_tensile * -pj / (rhoj * rhoj) : 0.0;
          if (ri + rj > 0) {
            const Real f = Kernel::w(r, hbar) / Kernel::w(spacing_, hbar);
            const Real f2 = f * f;
            tensile = (ri + rj) * f2 * f2;
          }
        }
        const Real vol_j = mj / rhoj;
        const Real vdotgw = vij.dot(gw);
        acc -= (vol_j * (pi + pj) * inv_rhoi + mj * (visc + tensile)) * gw;
        // At a wall the density sees the wall's own velocity (zero), as in Adami et al.;
        // mirroring the fluid velocity there instead held shocked gas better in a shock tube
        // but pushed a dam-break surge into the floor (tests/verification/sph_*).
        drho += vol_j * vdotgw;
        de += (vol_j * (wall ? pi + pj : pi) * inv_rhoi + (wall ? 1.0 : 0.5) * mj * visc) * vdotgw;
        if (mu_visc > 0) {
          // Paper eq. 36 (Lo & Shao 2002) with equal viscosities: k <= 0 since r . grad W <= 0.
          const Real k = 2 * mu_visc * rij.dot(gw) / (rhoi * rhoj * (r2 + eta2));
          acc += mj * k * vij_visc;
          // Heating equals the work the viscous force takes out (v_ij . v_ij_visc: |v_ij|^2
          // for particle pairs, v_i . (v_i - v_mirror) at a no-slip wall).
          de -= (wall ? 1.0 : 0.5) * mj * k * vij.dot(vij_visc);
        }
        if (eps_xsph > 0) xsph -= (mj / (0.5 * (rhoi + rhoj))) * Kernel::w(r, hbar) * vij;
      };

      for (const Index j : list_.of(i))
        pair(xi - x_[j], h_[j], m_[j], rho_[j], p_[j], c_[j], v_[j], v_[j], false);
      if (walls)
        for (const Index w : fluid_to_wall_.of(i))
          pair(xi - wall_x_[w], h0_, wall_rho_[w] * cell_volume_, wall_rho_[w], wall_p_[w],
               wall_c_[w], Vec<D>::Zero(), wall_v_[w], true);
      if (ghosts)
        for (const Index k : fluid_to_ghost_.of(i)) {
          const Index j = ghost_parent_[k];
          pair(xi - ghost_x_[k], h_[j], m_[j], rho_[j], ghost_p_[k], c_[j], ghost_v_[k],
               ghost_v_[k], false);
        }

      a_[i] = acc + g;
      drho_[i] = rhoi * drho;
      de_[i] = de;
      dx_xsph_[i] = eps_xsph * xsph;
      dt_cv_[i] = hi / (ci + mu_max);
    });
  }

  std::string name_;
  materials::EosParams eos_;
  Settings cfg_;
  Real spacing_;
  Vec<D> gravity_, domain_lo_, domain_hi_;
  bool outflow_remove_ = false;  // domain.outflow = "remove" (remove_outflow)
  bool is_explosive_ = false;
  Real detonation_velocity_ = 0;
  Real rho_ref_ = 0;  // unreacted density rho0 and CJ density, for the beta burn
  Real rho_cj_ = 0;
  bool beta_burn_ = false;
  Real burn_width_ = 0;  // distance over which F1 ramps from 0 to 1 [m]
  Real cell_volume_ = 0;
  Real h0_ = 0;

  fields::FieldSet<D> f_;
  std::vector<std::int64_t>& id_;
  std::vector<Vec<D>>& x_;
  std::vector<Vec<D>>& v_;
  std::vector<Real>& m_;
  std::vector<Real>& rho_;
  std::vector<Real>& e_;
  std::vector<Real>& h_;
  std::vector<Real>& p_;
  std::vector<Real>& c_;
  std::vector<Real>& burn_;
  std::vector<Real>& light_;
  std::vector<Vec<D>>& a_;
  std::vector<Real>& drho_;
  std::vector<Real>& de_;
  std::vector<Vec<D>>& dx_xsph_;
  std::vector<Vec<D>>& vh_;
  std::vector<Real>& rhoh_;
  std::vector<Real>& eh_;
  std::vector<Real>& dt_cv_;
  std::vector<Vec<D>>& fc_;             // force of the contacts with other parts (in a_ too)
  std::vector<Real>& surface_offset_;   // parts::ContactPoints::surface_offset
  std::vector<Real>& surface_overlap_;  // parts::ContactPoints::surface_overlap
  mutable std::vector<Real> contact_radius_;
  Real contact_work_ = 0;  // work of the contact forces on the part [J]
  Real last_dt_ = 0;
  bool contact_pending_ = false;  // moved since the contact forces were set

  // Fixed wall particles (not part of the FieldSet: they are not entities of the part).
  std::vector<Vec<D>> wall_x_, wall_mirror_;
  std::vector<Real> wall_p_, wall_rho_, wall_c_;
  std::vector<Vec<D>> wall_v_;

  // Mirror images behind free-slip walls (select_ghosts): parent index, reflection (-1 on the
  // mirrored axes) and offset (twice the face coordinate there), and the image's state.
  std::vector<Index> ghost_parent_;
  std::vector<Vec<D>> ghost_sign_, ghost_offset_, ghost_x_, ghost_v_;
  std::vector<Real> ghost_p_;

  neighbors::NeighborList list_, wall_to_fluid_, fluid_to_wall_, fluid_to_ghost_;
  Real h_max_ = 0;
  Real external_work_ = 0;
  bool has_walls_ = false;
  Index reflections_ = 0;
  Real max_penetration_ = 0;  // deepest crossing of a walled face that was reflected [m]
  neighbors::VerletSkin<D> skin_{kSkin};

  // Particles removed beyond the domain box (outflow = "remove"): how many, their mass [kg] and
  // their kinetic + internal energy when removed [J] (eroded_j).
  Index left_count_ = 0;
  Real left_mass_kg_ = 0, left_energy_j_ = 0;
  std::vector<std::uint8_t> keep_;  // scratch: remove_outflow's mask
  Real time_s_ = 0;                 // of the last force stage, for the log
};

}  // namespace

template <int D>
std::unique_ptr<parts::Part<D>> make_sph_part(const PartSettings& settings) {
  return std::make_unique<SphPart<D>>(settings);
}

template std::unique_ptr<parts::Part<2>> make_sph_part<2>(const PartSettings&);
template std::unique_ptr<parts::Part<3>> make_sph_part<3>(const PartSettings&);

}  // namespace crater::sph
