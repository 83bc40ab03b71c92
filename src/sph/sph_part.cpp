// SPH equations as implemented (docs/theory.md has them with the paper's numbers):
//   continuity (32):  d rho_i/dt = sum_j m_j (v_i - v_j) . grad_i W_ij
//   momentum (34):    d v_i/dt   = -sum_j m_j (p_i/rho_i^2 + p_j/rho_j^2 + Pi_ij) grad_i W_ij + g
//   energy:           d e_i/dt   = 1/2 sum_j m_j (p_i/rho_i^2 + p_j/rho_j^2 + Pi_ij)
//                                        (v_i - v_j) . grad_i W_ij
//   Monaghan viscosity: Pi_ij = (-alpha cbar_ij mu_ij + beta mu_ij^2) / rhobar_ij when
//                       v_ij . r_ij < 0, mu_ij = hbar v_ij . r_ij / (r_ij^2 + 0.01 hbar^2)
// W_ij uses the pair's mean smoothing length hbar = (h_i + h_j)/2, so grad_i W_ij = -grad_j W_ji
// and pair forces are equal and opposite: momentum is conserved to round-off, and total energy
// (kinetic + internal) is conserved by the continuous equations.
// Each particle gathers over its own neighbour list (ascending j), so the sums are evaluated in
// the same order for any number of threads (bit-identical results).
#include "sph/sph_part.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <cmath>
#include <limits>

#include "fields/field_set.hpp"
#include "materials/eos/eos.hpp"
#include "neighbors/cell_grid.hpp"
#include "neighbors/neighbor_list.hpp"
#include "parallel/parallel.hpp"
#include "sph/kernels.hpp"

namespace crater::sph {
namespace {

using fields::kOutput;
using fields::kRestart;
using fields::kStateRoles;

constexpr Index kResortEvery = 25;  // steps between re-sorting particles by cell (locality)

template <int D>
Vec<D> to_vec(const io::Vec3& a) {
  Vec<D> v;
  for (int d = 0; d < D; ++d)
    v[d] = a[static_cast<std::size_t>(d)];
  return v;
}

template <int D>
bool inside(const io::RegionConfig& r, const Vec<D>& x) {
  if (r.type == io::RegionType::Box) {
    for (int d = 0; d < D; ++d)
      if (x[d] < r.min_m[static_cast<std::size_t>(d)] ||
          x[d] > r.max_m[static_cast<std::size_t>(d)])
        return false;
    return true;
  }
  return (x - to_vec<D>(r.center_m)).norm() <= r.radius_m;
}

/// Particles at the centres of a lattice of pitch s over the region's bounding box, kept when
/// inside the region. Each particle stands for a cell of volume s^D.
template <int D>
std::vector<Vec<D>> lattice(const io::RegionConfig& r, Real s) {
  Vec<D> lo, hi;
  for (int d = 0; d < D; ++d) {
    const auto k = static_cast<std::size_t>(d);
    lo[d] = r.type == io::RegionType::Box ? r.min_m[k] : r.center_m[k] - r.radius_m;
    hi[d] = r.type == io::RegionType::Box ? r.max_m[k] : r.center_m[k] + r.radius_m;
  }
  IVec<D> n;
  for (int d = 0; d < D; ++d)
    n[d] = std::max<std::int64_t>(
        1, static_cast<std::int64_t>(std::floor((hi[d] - lo[d]) / s + 1e-9)));
  // Centre the lattice in the bounding box.
  Vec<D> start;
  for (int d = 0; d < D; ++d)
    start[d] = lo[d] + 0.5 * ((hi[d] - lo[d]) - (n[d] - 1) * s);
  std::vector<Vec<D>> pts;
  IVec<D> i = IVec<D>::Zero();
  while (true) {
    Vec<D> x;
    for (int d = 0; d < D; ++d)
      x[d] = start[d] + static_cast<Real>(i[d]) * s;
    if (inside<D>(r, x)) pts.push_back(x);
    int d = 0;
    while (d < D && ++i[d] == n[d])
      i[d++] = 0;
    if (d == D) break;
  }
  return pts;
}

template <int D>
class SphPart final : public solver::Part<D> {
 public:
  SphPart(const io::Config& c, const io::PartConfig& pc)
      : name_(pc.name),
        eos_(c.materials[pc.material].eos),
        cfg_(pc.sph),
        spacing_(pc.spacing_m),
        gravity_(to_vec<D>(c.domain.gravity_m_s2)),
        domain_lo_(to_vec<D>(c.domain.min_m)),
        domain_hi_(to_vec<D>(c.domain.max_m)),
        id_(f_.add_integer("id", "1", kStateRoles)),
        x_(f_.add_vector("position", "m", kRestart | fields::kHalo)),
        v_(f_.add_vector("velocity", "m/s", kStateRoles)),
        a_(f_.add_vector("acceleration", "m/s^2", fields::kNone)),
        m_(f_.add_scalar("mass", "kg", kStateRoles)),
        rho_(f_.add_scalar("density", "kg/m^3", kStateRoles)),
        e_(f_.add_scalar("specific_energy", "J/kg", kStateRoles)),
        h_(f_.add_scalar("smoothing_length", "m", kStateRoles)),
        p_(f_.add_scalar("pressure", "Pa", kOutput)),
        c_(f_.add_scalar("sound_speed", "m/s", kOutput)),
        light_(f_.add_scalar("lighting_time", "s", kRestart | fields::kHalo)),
        burn_(f_.add_scalar("burn_fraction", "1", kOutput)),
        drho_(f_.add_scalar("density_rate", "kg/m^3/s", fields::kNone)),
        de_(f_.add_scalar("energy_rate", "W/kg", fields::kNone)),
        dt_cv_(f_.add_scalar("dt_signal", "s", fields::kNone)) {
    const auto& mat = c.materials[pc.material];
    const std::vector<Vec<D>> pts = lattice<D>(pc.region, spacing_);
    const Index n = static_cast<Index>(pts.size());
    f_.resize(n);
    const Real rho0 = pc.initial.density_kg_m3.value_or(mat.rho0_kg_m3);
    const Real cell_volume = std::pow(spacing_, D);
    const Real h0 = cfg_.h_factor * spacing_;
    const Vec<D> v0 = to_vec<D>(pc.initial.velocity_m_s);

    // Initial specific internal energy from the material and the initial pressure.
    Real e0 = 0;
    if (const auto* jwl = std::get_if<materials::JwlParams>(&eos_)) {
      e0 = jwl->e0_j_m3 / jwl->rho0_kg_m3;
      detonation_velocity_ = jwl->d_cj_m_s;
      is_explosive_ = true;
    } else if (const auto* gas = std::get_if<materials::IdealGasParams>(&eos_)) {
      e0 = pc.initial.pressure_pa.value_or(0.0) / ((gas->gamma - 1) * rho0);
    }

    for (Index i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      id_[k] = i;
      x_[k] = pts[k];
      v_[k] = v0;
      m_[k] = rho0 * cell_volume;
      rho_[k] = rho0;
      e_[k] = e0;
      h_[k] = h0;
      // Programmed burn: a particle lights when the detonation front, running at D from the
      // nearest detonation point, reaches it. No points: all lit at t = 0.
      Real tl =
          is_explosive_ && !pc.detonations.empty() ? std::numeric_limits<Real>::infinity() : 0;
      for (const auto& dp : pc.detonations)
        tl = std::min(tl,
                      dp.time_s + (pts[k] - to_vec<D>(dp.point_m)).norm() / detonation_velocity_);
      light_[k] = tl;
    }
    h_max_ = h0;
    resort();
  }

  const std::string& name() const override { return name_; }
  const char* method() const override { return "sph"; }
  Index count() const override { return f_.size(); }
  Real mass_kg() const override {
    return parallel::deterministic_sum<Real>(f_.size(), [&](Index i) { return m_[i]; });
  }

  solver::StableStep stable_step() const override {
    // Monaghan & Kos (1999): dt = cfl * min(dt_f, dt_cv); dt_f = sqrt(h/|a|),
    // dt_cv = h / (c + max_j |h v_ij.r_ij / (r_ij^2 + eta^2)|) (computed in the force loop).
    const Index n = f_.size();
    solver::StableStep s;
    s.dt_s = std::numeric_limits<Real>::infinity();
    for (Index i = 0; i < n; ++i) {
      const Real an = a_[i].norm();
      const Real dt_f = an > 0 ? std::sqrt(h_[i] / an) : std::numeric_limits<Real>::infinity();
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
    t_ = t;
    if (++steps_since_sort_ >= kResortEvery) resort();
    neighbors::build_neighbor_list<D>(std::span<const Vec<D>>(x_), WendlandC2<D>::support * h_max_,
                                      neighbors::Pairs::Full, list_);
    update_eos(t);
    if (cfg_.kernel == KernelKind::WendlandC2)
      rates<WendlandC2<D>>();
    else
      rates<CubicSpline<D>>();
  }

  std::optional<solver::Fault> check() const override {
    const Index n = f_.size();
    // First offending particle in index order (deterministic); the loop is cheap next to rates.
    Index bad = n;
#pragma omp parallel for schedule(static) reduction(min : bad)
    for (Index i = 0; i < n; ++i) {
      bool ok = std::isfinite(drho_[i]) && std::isfinite(de_[i]) && a_[i].allFinite() &&
                rho_[i] > 0 && std::isfinite(p_[i]);
      for (int d = 0; d < D; ++d)
        ok = ok && x_[i][d] >= domain_lo_[d] && x_[i][d] <= domain_hi_[d];
      if (!ok) bad = std::min(bad, i);
    }
    if (bad == n) return std::nullopt;
    const Index i = bad;
    std::string what;
    bool in_domain = true;
    for (int d = 0; d < D; ++d)
      in_domain = in_domain && x_[i][d] >= domain_lo_[d] && x_[i][d] <= domain_hi_[d];
    if (!in_domain)
      what = fmt::format("particle left the domain at x = ({}) m; enlarge [domain]",
                         fmt::join(x_[i].data(), x_[i].data() + D, ", "));
    else if (!(rho_[i] > 0))
      what = fmt::format("non-positive density {} kg/m^3", rho_[i]);
    else
      what = fmt::format("non-finite rate or pressure (p = {} Pa, rho = {} kg/m^3, e = {} J/kg)",
                         p_[i], rho_[i], e_[i]);
    return solver::Fault{id_[i], what};
  }

  void advance(Real /*t*/, Real dt) override {
    const Index n = f_.size();
    const Real half = 0.5 * dt;
    parallel::for_each(n, [&](Index i) {
      v_[i] += half * a_[i];
      x_[i] += dt * v_[i];
      rho_[i] += dt * drho_[i];
      e_[i] += dt * de_[i];
    });
    // Work of gravity over the step, with the mid-step velocity.
    if (gravity_.squaredNorm() > 0)
      external_work_ += dt * parallel::deterministic_sum<Real>(
                                 n, [&](Index i) { return m_[i] * gravity_.dot(v_[i]); });
  }

  void finish_step(Real dt) override {
    const Real half = 0.5 * dt;
    parallel::for_each(f_.size(), [&](Index i) { v_[i] += half * a_[i]; });
  }

  solver::Energies energies() const override {
    struct KI {
      Real k = 0, u = 0;
      KI& operator+=(const KI& o) {
        k += o.k;
        u += o.u;
        return *this;
      }
    };
    const KI s = parallel::deterministic_sum<KI>(f_.size(), [&](Index i) {
      return KI{0.5 * m_[i] * v_[i].squaredNorm(), m_[i] * e_[i]};
    });
    solver::Energies en;
    en.kinetic_j = s.k;
    en.internal_j = s.u;
    en.external_work_j = external_work_;
    return en;
  }

  solver::Geometry<D> geometry() const override {
    solver::Geometry<D> g;
    g.points = &x_;
    return g;
  }
  std::vector<fields::FieldView> point_fields() const override {
    return f_.views(kOutput);
  }

 private:
  void resort() {
    steps_since_sort_ = 0;
    const auto order =
        neighbors::cell_sort_order<D>(std::span<const Vec<D>>(x_), WendlandC2<D>::support * h_max_);
    f_.permute(order);
  }

  // Pressure and sound speed from the EOS, with the programmed-burn fraction for explosives.
  void update_eos(Real t) {
    const Index n = f_.size();
    std::visit(
        [&](const auto& law) {
          parallel::for_each(n, [&](Index i) {
            Real burn = 1;
            if (is_explosive_) {
              // Wilkins' burn fraction: ramps from 0 to 1 while the front crosses 1.5 spacings.
              burn = t < light_[i]
                         ? 0.0
                         : std::min(1.0, (t - light_[i]) * detonation_velocity_ / (1.5 * spacing_));
            }
            burn_[i] = burn;
            const Real p = materials::eos_pressure_of(law, rho_[i], e_[i]);
            p_[i] = burn * p;
            c_[i] = materials::eos_sound_speed_of(law, rho_[i], e_[i], p);
          });
        },
        eos_);
  }

  template <class Kernel>
  void rates() {
    const Index n = f_.size();
    const Real alpha = cfg_.av_alpha, beta = cfg_.av_beta;
    const Vec<D> g = gravity_;
    parallel::for_each(n, [&](Index i) {
      const Vec<D> xi = x_[i], vi = v_[i];
      const Real hi = h_[i], rhoi = rho_[i], ci = c_[i];
      const Real pi_rho2 = p_[i] / (rhoi * rhoi);
      Vec<D> acc = Vec<D>::Zero();
      Real drho = 0, de = 0, mu_max = 0;
      for (const Index j : list_.of(i)) {
        const Vec<D> rij = xi - x_[j];
        const Real r2 = rij.squaredNorm();
        const Real hbar = 0.5 * (hi + h_[j]);
        if (r2 >= Kernel::support * Kernel::support * hbar * hbar) continue;
        const Real r = std::sqrt(r2);
        const Vec<D> gw = Kernel::grad_w(rij, r, hbar);
        const Vec<D> vij = vi - v_[j];
        const Real vdotr = vij.dot(rij);
        const Real mu = hbar * vdotr / (r2 + 0.01 * hbar * hbar);
        mu_max = std::max(mu_max, std::abs(mu));
        Real visc = 0;
        if (vdotr < 0) {
          const Real cbar = 0.5 * (ci + c_[j]);
          const Real rhobar = 0.5 * (rhoi + rho_[j]);
          visc = (-alpha * cbar * mu + beta * mu * mu) / rhobar;
        }
        const Real mj = m_[j];
        const Real coef = pi_rho2 + p_[j] / (rho_[j] * rho_[j]) + visc;
        const Real vdotgw = vij.dot(gw);
        drho += mj * vdotgw;
        acc -= mj * coef * gw;
        de += 0.5 * mj * coef * vdotgw;
      }
      a_[i] = acc + g;
      drho_[i] = drho;
      de_[i] = de;
      dt_cv_[i] = hi / (ci + mu_max);
    });
  }

  std::string name_;
  materials::EosParams eos_;
  io::SphConfig cfg_;
  Real spacing_;
  Vec<D> gravity_, domain_lo_, domain_hi_;
  bool is_explosive_ = false;
  Real detonation_velocity_ = 0;

  fields::FieldSet<D> f_;
  std::vector<std::int64_t>& id_;
  std::vector<Vec<D>>& x_;
  std::vector<Vec<D>>& v_;
  std::vector<Vec<D>>& a_;
  std::vector<Real>& m_;
  std::vector<Real>& rho_;
  std::vector<Real>& e_;
  std::vector<Real>& h_;
  std::vector<Real>& p_;
  std::vector<Real>& c_;
  std::vector<Real>& light_;
  std::vector<Real>& burn_;
  std::vector<Real>& drho_;
  std::vector<Real>& de_;
  std::vector<Real>& dt_cv_;

  neighbors::NeighborList list_;
  Real h_max_ = 0;
  Real t_ = 0;
  Real external_work_ = 0;
  Index steps_since_sort_ = 0;
};

}  // namespace

template <int D>
std::unique_ptr<solver::Part<D>> make_sph_part(const io::Config& config,
                                               const io::PartConfig& part) {
  return std::make_unique<SphPart<D>>(config, part);
}

template std::unique_ptr<solver::Part<2>> make_sph_part<2>(const io::Config&,
                                                           const io::PartConfig&);
template std::unique_ptr<solver::Part<3>> make_sph_part<3>(const io::Config&,
                                                           const io::PartConfig&);

}  // namespace crater::sph
