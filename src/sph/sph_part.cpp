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
//                                  + sum_j m_j alpha_u v_sig^u (e_i - e_j)/rhobar r_hat . grad_i W
//                                    (artificial conductivity, Price 2008; off by default)
//   Monaghan viscosity: Pi_ij = (-alpha cbar mu + beta mu^2) / rhobar for v_ij . r_ij < 0,
//                       mu = hbar v_ij . r_ij / (r_ij^2 + 0.01 hbar^2)
// Pairs use hbar = (h_i + h_j)/2, so grad_i W_ij = -grad_j W_ji and pair forces are equal and
// opposite: momentum is conserved to round-off; kinetic + internal energy is conserved by the
// semi-discrete equations (the energy equation is the one that balances the momentum
// equation's pressure work pair by pair), and by the wall terms (energy_rate, pair_terms.hpp).
// Each particle gathers over its own neighbour list (ascending j), so the sums are evaluated in
// the same order for any number of threads (bit-identical results). With density = "summation"
// the density is summed and h solved with it (summation.hpp), and the pressure terms take their
// grad-h form (pair_terms.hpp, gather_pair_grad_h).
#include "sph/sph_part.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>
#include <cmath>
#include <limits>

#include "fields/field_set.hpp"
#include "materials/eos/eos.hpp"
#include "neighbors/cell_grid.hpp"
#include "neighbors/pair_radius_list.hpp"
#include "neighbors/verlet_skin.hpp"
#include "parallel/parallel.hpp"
#include "parts/contact_points.hpp"
#include "parts/outflow.hpp"
#include "parts/region.hpp"
#include "sph/burn.hpp"
#include "sph/kernels.hpp"
#include "sph/pair_terms.hpp"
#include "sph/sph_setup.hpp"
#include "sph/sph_walls.hpp"
#include "sph/summation.hpp"

namespace crater::sph {
namespace {

using fields::kHalo;
using fields::kNone;
using fields::kOutput;
using fields::kRestart;
using fields::kStateRoles;

constexpr Real kSkin = 0.25;  // neighbour-list margin, as a fraction of a particle's support
constexpr Real kInf = std::numeric_limits<Real>::infinity();
// Summation density: h is at most this many times h_factor (m / rho0)^(1/D), the particle's h at
// the material's reference density (the wall and image lists are built for the largest h).
constexpr Real kMaxHGrowth = 3;

using parts::to_vec;

template <int D>
class SphPart final : public parts::Part<D> {
 public:
  explicit SphPart(const PartSettings& settings)
      : name_(settings.part.name),
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
        omega_(f_.add_scalar("grad_h_omega", "1", kNone)),
        h_list_(f_.add_scalar("list_smoothing_length", "m", kRestart)),
        h_wanted_(f_.add_scalar("wanted_smoothing_length", "m", kNone)),
        list_reach_(f_.add_scalar("list_reach", "m", kNone)),
        fc_(f_.add_vector("contact_force", "N", kRestart)),
        surface_offset_(f_.add_scalar("contact_surface_offset", "m", kRestart)),
        surface_overlap_(f_.add_scalar("contact_surface_overlap", "m", kRestart)) {
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
    // dt_cv = h / (c + max_j |mu_ij|) (max over neighbours, from the force loop); with the
    // artificial conductivity max_j |mu_ij| becomes max(max_j |mu_ij|, max_j alpha_u v_sig^u_ij),
    // the diffusion's own signal speed (explicit diffusion needs dt <~ h / (alpha_u v_sig^u));
    // with a laminar viscosity also Morris, Fox & Zhu (1997) eq. 12: dt_v = 0.125 h^2 rho / mu.
    parts::StableStep s;
    s.dt_s = kInf;
    const Real mu = cfg_.viscosity_pa_s;
    for (Index i = 0; i < f_.size(); ++i) {
      const Real an = a_[i].norm();
      const Real dt_f = an > 0 ? std::sqrt(h_[i] / an) : kInf;
      const Real dt_v = mu > 0 ? Real(0.125) * h_[i] * h_[i] * rho_[i] / mu : kInf;
      const Real dt_i = std::min(cfg_.cfl * std::min(dt_f, dt_cv_[i]), dt_v);
      if (dt_i < s.dt_s || (dt_i == s.dt_s && id_[i] < s.entity_id)) {  // ties: smallest id
        s.dt_s = dt_i;
        s.entity_id = id_[i];
        s.reason = dt_i == dt_v ? fmt::format("viscous limit, mu = {:.3g} Pa s", mu)
                   : dt_f < dt_cv_[i]
                       ? fmt::format("force criterion, |a| = {:.3g} m/s^2", an)
                       : fmt::format("CFL {} with sound speed {:.4g} m/s", cfg_.cfl, c_[i]);
      }
    }
    return s;
  }

  void compute_forces(Real t) override {
    time_s_ = t;
    if (summation()) {
      update_neighbors();
      if (cfg_.kernel == KernelKind::WendlandC2)
        summation_density<WendlandC2<D>>();
      else
        summation_density<CubicSpline<D>>();
    } else {
      update_smoothing_lengths();
    }
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
    const bool sum_rho = summation();  // the force stage sums the density of t + dt
    parallel::for_each(f_.size(), [&](Index i) {
      vh_[i] = v_[i] + half * a_[i];
      rhoh_[i] = rho_[i] + half * drho_[i];
      eh_[i] = e_[i] + half * de_[i];
      x_[i] += dt * (vh_[i] + dx_xsph_[i]);
      if (has_walls_) reflect_at_walls(i);
      v_[i] = vh_[i] + half * a_[i];
      if (!sum_rho) rho_[i] = rhoh_[i] + half * drho_[i];
      e_[i] = eh_[i] + half * de_[i];
    });
    contact_.moved(dt);
    next_contact_.started();
    // Work of gravity over the step, with the mid-step velocity.
    if (gravity_.squaredNorm() > 0)
      external_work_ += dt * parallel::deterministic_sum<Real>(
                                 f_.size(), [&](Index i) { return m_[i] * gravity_.dot(vh_[i]); });
  }

  void finish_step(Real dt) override {
    const Real half = 0.5 * dt;
    const bool sum_rho = summation();
    parallel::for_each(f_.size(), [&](Index i) {
      v_[i] = vh_[i] + half * a_[i];
      if (!sum_rho) rho_[i] = rhoh_[i] + half * drho_[i];
      e_[i] = eh_[i] + half * de_[i];
    });
    next_contact_.finished([&](const auto& f, const auto&) { take_contact(f); });
    if (outflow_remove_) remove_outflow();
  }

  /// Particles as contacts see them: spheres (disks) of half their volume-equivalent size,
  /// (m / rho)^(1/D) / 2, moving at the predicted velocity.
  std::optional<parts::ContactPoints<D>> contact_points() const override {
    contact_radius_.resize(static_cast<std::size_t>(f_.size()));
    parallel::for_each(
        f_.size(), [&](Index i) { contact_radius_[i] = Real(0.5) * dth_root<D>(m_[i] / rho_[i]); });
    return parts::ContactPoints<D>{.position = lagged_.view(x_),
                                   .velocity = &v_,
                                   .mass = &m_,
                                   .radius = &contact_radius_,
                                   .surface_offset = &surface_offset_,
                                   .surface_overlap = &surface_overlap_,
                                   .id = &id_};
  }

  void set_contact_lag(Real lag_s) override {
    // The drift of advance(): the half-step velocity and the XSPH correction.
    lagged_.set(x_, lag_s, [&](Index i) { return Vec<D>(vh_[i] + dx_xsph_[i]); });
  }
  void set_next_contact_forces(const std::vector<Vec<D>>& force,
                               const std::vector<AxialVec<D>>& torque) override {
    if (static_cast<Index>(force.size()) != f_.size())
      throw std::logic_error("sph: next contact forces for another particle count");
    next_contact_.set(force, torque, [&](const auto& f, const auto&) { take_contact(f); });
  }

  void add_contact_forces(const std::vector<Vec<D>>& force,
                          const std::vector<AxialVec<D>>& /*torque*/) override {
    if (static_cast<Index>(force.size()) != f_.size())
      throw std::logic_error("sph: contact forces for another particle count");
    contact_.settle(f_.size(), [&](Index i) { return vh_[i].dot(fc_[i] + force[i]); });
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
    en.contact_j = -contact_.work_j;
    en.eroded_j = outflow_.energy_j();
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
    if (outflow_remove_) outflow_.add_diagnostics(d);
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

  // A particle that crossed a walled face is put back (sph_walls.hpp, reflect_at_walls),
  // counted in summary.json: `wall_reflections` and `wall_max_penetration_m`.
  void reflect_at_walls(Index i) {
    const Reflection r =
        sph::reflect_at_walls<D>(cfg_.walls, domain_lo_, domain_hi_, x_[i], vh_[i], a_[i]);
    if (r.faces > 0) {
#pragma omp critical(crater_sph_reflections)
      {
        reflections_ += r.faces;
        max_penetration_ = std::max(max_penetration_, r.deepest);
      }
    }
  }

  bool in_domain(Index i) const {
    return parts::in_box<D>(x_[i], domain_lo_, domain_hi_);
  }
  bool healthy(Index i) const {
    return std::isfinite(drho_[i]) && std::isfinite(de_[i]) && a_[i].allFinite() && rho_[i] > 0 &&
           std::isfinite(p_[i]) && (outflow_remove_ ? x_[i].allFinite() : in_domain(i));
  }

  // outflow = "remove" (parts/outflow.hpp): particles beyond the domain box leave the model at
  // the end of the step, with the velocity, density and energy of t + dt; their kinetic and
  // internal energy goes to eroded_j. The rest keep their order: the same numbers for any
  // thread count, and after a restart from this state (which holds the rebuilt lists' skin).
  void remove_outflow() {
    const Index n = f_.size();
    const Index leaving = outflow_.mark(n, [&](Index i) { return in_domain(i); });
    if (leaving == 0) return;
    const auto removed = parallel::deterministic_sum<parts::Removed>(n, [&](Index i) {
      if (outflow_.kept(i)) return parts::Removed{};
      return parts::Removed{m_[i], 0.5 * m_[i] * v_[i].squaredNorm() + m_[i] * e_[i]};
    });
    outflow_.book(name_, "particles", time_s_, leaving, removed);
    outflow_.compact(f_);
    // The rates of the state without them (lists rebuilt, in their order), the contact forces
    // added as in add_contact_forces: the next half kick owes nothing to a removed particle and
    // the pair terms stay equal and opposite. Without this their pressure work over that half
    // kick went unbooked (1 % of the energy of the gas disk of tests/verification/outflow).
    rebuild_lists();
    pair_rates();
    parallel::for_each(f_.size(), [&](Index i) { a_[i] += fc_[i] / m_[i]; });
  }

  // Verlet lists (1967) per particle: i's serve h up to h_list_i, a pair is listed when within
  // (1 + kSkin) x the support of the larger h_list at the rebuild, and they are kept while no
  // support plus twice the largest displacement outgrows that. Re-sorted at rebuilds (locality).
  void update_neighbors() {
    if (!lists_stale()) return;
    resort();
    rebuild_lists();
  }

  bool lists_stale() const {
    const Index n = f_.size();
    if (skin_.radius() <= 0 || skin_.positions().size() != at(n)) return true;
    const Real excess =
        parallel::max_over(n, -kInf, [&](Index i) { return h_[i] - (1 + kSkin) * h_list_[i]; });
    return WendlandC2<D>::support * excess + 2 * skin_.moved(std::span<const Vec<D>>(x_)) > 0;
  }

  void rebuild_lists() {  // i's lists serve h_i or more (asked); all the largest within 2x
    parallel::for_each(f_.size(), [&](Index i) { h_list_[i] = std::max(h_[i], h_wanted_[i]); });
    const Real lo = -parallel::max_over(f_.size(), -kInf, [&](Index i) { return -h_list_[i]; });
    h_max_ =
        std::max(h_max_, parallel::max_over(f_.size(), 0.0, [&](Index i) { return h_list_[i]; }));
    if (h_max_ <= 2 * lo) parallel::for_each(f_.size(), [&](Index i) { h_list_[i] = h_max_; });
    skin_.built(std::span<const Vec<D>>(x_), WendlandC2<D>::support * h_max_);
    build_lists();
  }

  // Lists at the last rebuild's positions (a restart: the same); walls/images: the largest h.
  void build_lists() {
    const std::span<const Vec<D>> xb = skin_.positions();
    const Real radius = skin_.radius();
    parallel::for_each(f_.size(), [&](Index i) {  // std::min(radius, NaN) is radius
      list_reach_[i] = std::min(radius, (1 + kSkin) * WendlandC2<D>::support * h_list_[i]);
    });
    neighbors::build_pair_radius_list<D>(xb, std::span<const Real>(list_reach_), list_, levels_);
    if (!wall_x_.empty()) {
      neighbors::build_cross_list<D>(std::span<const Vec<D>>(wall_x_), xb, radius, wall_to_fluid_);
      neighbors::build_cross_list<D>(xb, std::span<const Vec<D>>(wall_x_), radius, fluid_to_wall_);
    }
    if (has_walls_ && !cfg_.wall_no_slip) {
      ghosts_.select(xb, radius, cfg_.walls, domain_lo_, domain_hi_);
      ghosts_.place(xb);
      neighbors::build_cross_list<D>(xb, std::span<const Vec<D>>(ghosts_.x), radius,
                                     fluid_to_ghost_);
    }
  }

  // The checkpoint layout, for both directions (Self: const for writing).
  template <class Archive, class Self>
  static void archive(Archive& a, Self& s) {
    a.tag("sph");
    a.block(s.f_);
    a.value(s.h_max_);
    a.value(s.external_work_);
    a.value(s.contact_.work_j);
    a.value(s.contact_.last_dt_s);
    a.value(s.contact_.pending);
    a.value(s.reflections_);
    a.value(s.max_penetration_);
    a.block(s.skin_);
    a.block(s.outflow_);
  }

 public:
  void save_state(parts::StateWriter& w) const override {
    archive(w, *this);
  }
  void load_state(parts::StateReader& r) override {
    archive(r, *this);
    if (skin_.radius() > 0) build_lists();
  }

 private:
  // The mirror images' positions, velocities and pressures (sph_walls.hpp, Ghosts).
  void ghost_state() {
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
    const auto order = neighbors::cell_sort_order<D>(  // within a cell by id: canonical
        std::span<const Vec<D>>(x_), WendlandC2<D>::support * h_max_, std::span(id_));
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

  bool summation() const {
    return cfg_.density == DensityKind::Summation;
  }

  // density = "summation" (summation.hpp): each particle's rho, h and Omega from its lists.
  // A particle that needs a larger h than its lists serve asks for a rebuild, where its lists
  // serve twice that h (capped), and the whole pass repeats from the h reached. Each
  // particle reads only positions, masses and its own h, in its lists' order: the same numbers
  // for any thread count.
  template <class Kernel>
  void summation_density() {
    const Index n = f_.size();
    const Real hf = cfg_.h_factor;
    const Real inv_d = Real(1) / D;
    for (int pass = 0;; ++pass) {
      const Real moved = skin_.moved(std::span<const Vec<D>>(x_));
      if (!ghosts_.empty()) ghosts_.place(std::span<const Vec<D>>(x_));
      const Real wanted = parallel::max_over(
          n, 0.0,
          [&](Index i) {
            const Real cap = kMaxHGrowth * hf * std::pow(m_[i] / rho_material_, inv_d);
            const Real reach_h =
                ((1 + kSkin) * WendlandC2<D>::support * h_list_[i] - 2 * moved) / Kernel::support;
            const DensitySolve s = solve_density<Kernel>(
                m_[i], h_[i], std::min(cap, reach_h), cap, hf, cfg_.variable_h,
                [&](Real h) { return kernel_sum<Kernel>(i, h); });
            rho_[i] = s.rho;
            h_[i] = s.h;
            omega_[i] = s.omega;
            h_wanted_[i] = s.want > 0 ? std::min(2 * s.want, cap) : 0;
            return s.want;
          },
          parallel::Cost::heavy);
      if (wanted <= 0 || pass >= 8) break;
      resort();
      rebuild_lists();
    }
    std::fill(h_wanted_.begin(), h_wanted_.end(), Real(0));
    h_max_ = std::max(h0_, parallel::max_over(n, 0.0, [&](Index i) { return h_[i]; }));
  }

  // The kernel sums of particle i at h over itself, its fluid neighbours, its mirror images and
  // the wall particles (each list in ascending order).
  template <class Kernel>
  KernelSum<Kernel> kernel_sum(Index i, Real h) const {
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
  void update_eos(Real t) {
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

  template <class Kernel>
  void wall_state() {
    if (wall_x_.empty()) return;
    average_wall_state<Kernel, D>(wall_x_, wall_mirror_, wall_to_fluid_,
                                  FluidArrays<D>{x_, h_, p_, rho_, c_, v_}, h0_, gravity_,
                                  cfg_.wall_no_slip, wall_);
  }

  // The rates of every particle: the pair terms (pair_terms.hpp, gather_pair) over its fluid
  // neighbours, then its wall particles, then the mirror images, each list in ascending order.
  template <class Kernel>
  void rates() {
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

  // Particle i and its three kinds of neighbours as the pair terms see them. A wall particle
  // has the density of its fluid average on a cell of the wall lattice, and moves with the
  // wall (zero velocity) but shows the viscous terms the mirrored fluid velocity; a mirror
  // image is its parent with its own position, velocity and pressure.
  [[gnu::always_inline]] Centre<D> centre(const RateParams& c, Index i) const {
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
  [[gnu::always_inline]] Neighbour<D> fluid_neighbour(const Vec<D>& rij, Index j) const {
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
  [[gnu::always_inline]] Neighbour<D> wall_neighbour(const Vec<D>& rij, Index w) const {
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
  [[gnu::always_inline]] Neighbour<D> ghost_neighbour(const Vec<D>& rij, Index g) const {
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
  [[gnu::always_inline]] static Neighbour<D> with_grad_h(Neighbour<D> n, Real h, Real omega) {
    n.h = h;
    n.p_omega = n.p / (omega * n.rho * n.rho);
    return n;
  }

  std::string name_;
  materials::EosParams eos_;
  Settings cfg_;
  Real spacing_;
  Real rho_material_;  // the material's reference density (the summation density's h cap)
  Vec<D> gravity_, domain_lo_, domain_hi_;
  bool outflow_remove_ = false;  // domain.outflow = "remove" (remove_outflow)
  ProgrammedBurn burn_model_;
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
  std::vector<Real>& omega_;       // summation density: Omega_i of the grad-h terms (1 otherwise)
  std::vector<Real>& h_list_;      // the h its lists serve (rebuild_lists); saved: same lists
  std::vector<Real>& h_wanted_;    // summation density: a larger h than the lists serve, or 0
  std::vector<Real>& list_reach_;  // build_lists: (1 + kSkin) x the support of h_list
  std::vector<Vec<D>>& fc_;        // force of the contacts with other parts (in a_ too)
  parts::LaggedPositions<D> lagged_;          // positions the contacts see (multi-rate stepping)
  parts::NextContactForces<D> next_contact_;  // for the next step's first half kick
  /// Multi-rate: the next step starts with other contact forces than the last one ended with.
  void take_contact(const std::vector<Vec<D>>& force) {
    parallel::for_each(f_.size(), [&](Index i) {
      a_[i] += (force[at(i)] - fc_[i]) / m_[i];
      fc_[i] = force[at(i)];
    });
  }
  std::vector<Real>& surface_offset_;   // parts::ContactPoints::surface_offset
  std::vector<Real>& surface_overlap_;  // parts::ContactPoints::surface_overlap
  mutable std::vector<Real> contact_radius_;
  parts::ContactWork contact_;  // work of the contact forces on the part

  // Fixed wall particles (not part of the FieldSet: they are not entities of the part).
  std::vector<Vec<D>> wall_x_, wall_mirror_;
  WallState<D> wall_;  // their pressure, density, sound speed and velocity (average_wall_state)

  Ghosts<D> ghosts_;  // mirror images behind free-slip walls

  neighbors::NeighborList list_, wall_to_fluid_, fluid_to_wall_, fluid_to_ghost_;
  std::vector<neighbors::NeighborList> levels_;  // build_pair_radius_list's scratch
  Real h_max_ = 0;
  Real external_work_ = 0;
  bool has_walls_ = false;
  Index reflections_ = 0;
  Real max_penetration_ = 0;  // deepest crossing of a walled face that was reflected [m]
  neighbors::VerletSkin<D> skin_{kSkin};

  // Particles removed beyond the domain box (outflow = "remove"): how many, their mass [kg] and
  // their kinetic + internal energy when removed [J] (eroded_j).
  parts::OutflowRemoval outflow_;
  Real time_s_ = 0;  // of the last force stage, for the log
};

}  // namespace

template <int D>
std::unique_ptr<parts::Part<D>> make_sph_part(const PartSettings& settings) {
  return std::make_unique<SphPart<D>>(settings);
}

template std::unique_ptr<parts::Part<2>> make_sph_part<2>(const PartSettings&);
template std::unique_ptr<parts::Part<3>> make_sph_part<3>(const PartSettings&);

}  // namespace crater::sph
