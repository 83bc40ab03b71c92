// The DEM part's walls (dem_part_impl.hpp): the planes of the rigid and absorbing faces, the
// moving walls (velocity or servo stress: their motion, loads, work and history columns), the
// absorbing walls' impedance and static reactions, and the wall guard. The walls' forces on
// the grains are taken in the force stage (dem_pair_loop.cpp: rigid_wall_contacts,
// absorbing_wall_loads).
#include <Eigen/Geometry>  // cross products of 3D contact laws

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>

#include "dem/dem_part_impl.hpp"

namespace crater::dem::detail {

// The planes of the rigid walls (a moving wall's at its position_m) and of every face (the
// guard), the box beyond which a grain touches no rigid wall, and the walls' contact histories.
// A settling part's walls stand still (moving_ stays empty).
template <int D>
void DemPart<D>::init_walls(bool settling) {
  const Index n = f_.size();
  for (const parts::Face face : cfg_.walls)
    wall_planes_.push_back(wall_plane(face));
  // One moving wall per face, in the order of the faces' first entries.
  for (const WallMotion& m : cfg_.wall_motion) {
    const auto slot = static_cast<std::size_t>(
        std::find(cfg_.walls.begin(), cfg_.walls.end(), m.face) - cfg_.walls.begin());
    if (m.position_m) wall_planes_[slot].plane = *m.position_m;
    const bool known = std::any_of(moving_.begin(), moving_.end(),
                                   [&](const MovingWall& mw) { return mw.slot == slot; });
    if (!settling && !known) moving_.push_back(MovingWall{.slot = slot});
  }
  for (MovingWall& mw : moving_)
    mw.plane = wall_planes_[mw.slot].plane;
  // The absorbing faces are not guarded: a grain whose centre crosses one leaves the model
  // (remove_outflow), as through a transmitting boundary.
  guard_planes_ = wall_planes_;
  place_walls();
  // The fixed bodies take wall slots after the faces (they are neither in the guard nor in
  // the clear box: rigid_wall_contacts tests them for every grain).
  for (const parts::RegionConfig& b : bodies_) {
    WallPlane w;
    w.body = &b;
    wall_planes_.push_back(w);
  }
  const std::size_t wall_slots = static_cast<std::size_t>(n) * wall_planes_.size();
  wall_xi_.assign(wall_slots, Vec<D>::Zero());
  if (wall_planes_.size() > 32) throw std::logic_error("dem: more than 32 walls and bodies");
  wall_live_.assign(static_cast<std::size_t>(n), 0);
  if (rolling_.friction > 0) wall_roll_.assign(wall_slots, angular_zero<D>());
  if (!moving_.empty()) wall_load_.assign(wall_slots, WallLoad{});
}

// The clear box (the faces of cfg_.walls, +-inf where there is none) and the guard box (inside
// every rigid face) from the planes as they stand.
template <int D>
void DemPart<D>::place_walls() {
  clear_lo_ = Vec<D>::Constant(-std::numeric_limits<Real>::infinity());
  clear_hi_ = Vec<D>::Constant(std::numeric_limits<Real>::infinity());
  for (std::size_t w = 0; w < cfg_.walls.size(); ++w) {
    const WallPlane& p = wall_planes_[w];
    (p.upper ? clear_hi_ : clear_lo_)[p.axis] = p.plane;
  }
  guard_lo_ = clear_lo_;
  guard_hi_ = clear_hi_;
  for (const WallPlane& w : guard_planes_)
    if (w.upper)
      guard_hi_[w.axis] = std::min(guard_hi_[w.axis], w.plane);
    else
      guard_lo_[w.axis] = std::max(guard_lo_[w.axis], w.plane);
}

template <int D>
Real DemPart<D>::wall_area(int axis) const {
  Real area = 1;  // 2D: per metre of depth
  for (int d = 0; d < D; ++d) {
    if (d == axis) continue;
    const Real hi = std::isfinite(clear_hi_[d]) ? clear_hi_[d] : domain_hi_[d];
    const Real lo = std::isfinite(clear_lo_[d]) ? clear_lo_[d] : domain_lo_[d];
    area *= hi - lo;
  }
  return area;
}

namespace {

// The outward travel [m] of a wall of prescribed speed (WallDrive::Velocity) over [t0, t1]:
// the integral of v(tau) = velocity min(1, (tau - start) / ramp) over the part of [t0, t1] in
// its window, exact (a step that straddles the window's ends or the ramp moves by what the
// speed gives, not by the speed at its start).
Real prescribed_travel(const WallMotion& m, Real t0, Real t1) {
  const Real a = std::max(t0, m.start_s), b = std::min(t1, m.end_s);
  if (!(b > a)) return 0;
  const Real ramp = m.ramp_s;
  auto from_start = [&](Real tau) {  // the integral from start_s to tau, over the velocity
    const Real s = tau - m.start_s;
    return ramp > 0 && s < ramp ? s * s / (2 * ramp) : s - ramp / 2;
  };
  return m.velocity_m_s * (from_start(b) - from_start(a));
}

// The moving walls' loads: per wall (at most one per face) its force, elastic force and
// stiffness (measure_walls).
constexpr std::size_t kMovingWalls = 6;
constexpr std::size_t kWallSums = 3 * kMovingWalls;
using WallSums = std::array<Real, kWallSums>;

}  // namespace

// The moving walls over the step [t, t + dt] (advance, before the grains drift), each by its
// face's entries (their windows [start_s, end_s) are apart; none: it stands still). A wall of
// prescribed speed moves by its integral over the step (reached linearly over ramp_s). A servo
// wall (stress_pa, the entry whose window holds t) by the law of PFC's and YADE's servos,
//   v_out = alpha (F_el - sigma* A) / (K dt),  |v_out| <= v_max,
// F_el and K the elastic normal force and stiffness of its contacts at the last force stage, A
// its current area: a step closes the fraction alpha of the force error if the grains stood
// still; with no contact it moves in at v_max. The contacts' dashpots are left out of the
// loop: they answer the wall's own speed at once (gamma_n v, far above K v dt with Hertz
// contacts at the DEM step), and a servo on the whole force chattered step by step (2D sand
// bed, gain 0.5); a wall that follows its grains steadily carries no dashpot force. A wall
// stops at the domain's face.
template <int D>
void DemPart<D>::move_walls(Real t, Real dt) {
  if (moving_.empty()) return;
  for (MovingWall& mw : moving_) {
    const WallPlane& p = wall_planes_[mw.slot];
    Real travel = 0;
    const WallMotion* servo = nullptr;
    for (const WallMotion& m : cfg_.wall_motion) {
      if (m.face != cfg_.walls[mw.slot]) continue;
      if (m.drive == WallDrive::Velocity)
        travel += prescribed_travel(m, t, t + dt);
      else if (t >= m.start_s && t < m.end_s)
        servo = &m;
    }
    Real v = dt > 0 ? travel / dt : 0;
    if (servo) {
      const WallMotion& m = *servo;
      const Real excess = mw.elastic_n - m.stress_pa * wall_area(p.axis);
      v = mw.stiffness_n_m > 0 && dt > 0 ? m.servo_gain * excess / (mw.stiffness_n_m * dt)
                                         : -m.max_speed_m_s;
      v = std::clamp(v, -m.max_speed_m_s, m.max_speed_m_s);
      travel = v * dt;
    }
    const Real out = p.upper ? 1 : -1;
    const Real free = mw.plane + out * travel;
    const Real plane = std::clamp(free, domain_lo_[p.axis], domain_hi_[p.axis]);
    mw.moved_out += out * (plane - mw.plane);
    mw.velocity_out = plane == free ? v : (dt > 0 ? out * (plane - mw.plane) / dt : 0);
    mw.plane = plane;
  }
  set_wall_planes();
}

// The moving walls' planes (in wall_planes_ and guard_planes_) and velocities from moving_,
// then the clear and guard boxes.
template <int D>
void DemPart<D>::set_wall_planes() {
  if (moving_.empty()) return;
  for (const MovingWall& mw : moving_) {
    WallPlane& p = wall_planes_[mw.slot];
    p.plane = mw.plane;
    guard_planes_[mw.slot].plane = mw.plane;
    p.velocity = Vec<D>::Zero();
    p.velocity[p.axis] = (p.upper ? 1 : -1) * mw.velocity_out;
  }
  place_walls();
}

// The moving walls' loads of this force stage, each a sum over the own grains that touch a
// wall, with the same bits whichever rank holds which grain and on any thread count
// (parallel::reproducible_sums: every rank gets the whole sums, and moves its walls alike), and
// the work they did on the grains over the step, by the trapezoidal rule:
// W = -(F_old + F_new)/2 x (outward move), booked as external work (the root's book on ranks:
// energies() adds every rank's).
template <int D>
void DemPart<D>::measure_walls() {
  if (moving_.empty()) return;
  if (moving_.size() > kMovingWalls) throw std::logic_error("dem: more moving walls than faces");
  const std::size_t walls = wall_planes_.size();
  const auto touching = [&](Index i) {
    return !ghost(i) && wall_live_[static_cast<std::size_t>(i)] != 0;
  };
  // Per grain: the force, elastic force and stiffness of its contact with each moving wall.
  const auto loads = [&](Index i) {
    WallSums l{};
    const std::uint32_t live = wall_live_[static_cast<std::size_t>(i)];
    for (std::size_t k = 0; k < moving_.size(); ++k) {
      const std::size_t slot = moving_[k].slot;
      if (!(live >> slot & 1u)) continue;
      const WallLoad& q = wall_load_[static_cast<std::size_t>(i) * walls + slot];
      l[3 * k] = q.force;
      l[3 * k + 1] = q.elastic;
      l[3 * k + 2] = q.stiffness;
    }
    return l;
  };
  const auto s = parallel::reproducible_sums<kWallSums>(comm_, f_.size(), touching, loads);
  const bool books = !comm_ || comm_->root();
  for (std::size_t k = 0; k < moving_.size(); ++k) {
    MovingWall& mw = moving_[k];
    if (books) external_work_ -= 0.5 * (mw.force_n + s[3 * k]) * mw.moved_out;
    mw.moved_out = 0;
    mw.force_n = s[3 * k];
    mw.elastic_n = s[3 * k + 1];
    mw.stiffness_n_m = s[3 * k + 2];
  }
}

// history.csv: per moving wall, <part>_wall_<face>_position_m, _velocity_m_s (outward),
// _force_n (on the grains, compression > 0; 2D per metre) and _stress_pa (force / area).
template <int D>
std::vector<std::string> DemPart<D>::history_columns() const {
  static constexpr const char* kFaces[] = {"left", "right", "bottom", "top", "back", "front"};
  std::vector<std::string> cols;
  for (const MovingWall& mw : moving_) {
    const std::string base = name_ + "_wall_" + kFaces[static_cast<int>(cfg_.walls[mw.slot])] + "_";
    for (const char* q : {"position_m", "velocity_m_s", "force_n", "stress_pa"})
      cols.push_back(base + q);
  }
  return cols;
}

template <int D>
std::vector<Real> DemPart<D>::history_values() const {
  std::vector<Real> v;
  for (const MovingWall& mw : moving_) {
    const Real area = wall_area(wall_planes_[mw.slot].axis);
    v.insert(v.end(), {mw.plane, mw.velocity_out, mw.force_n, mw.force_n / area});
  }
  return v;
}

// The bed's impedance behind the absorbing walls (defaults from the grains, see the schema)
// and each touching grain's static reaction: the rigid wall law's elastic normal force at its
// overlap now (t = 0: after settling, or as placed).
template <int D>
void DemPart<D>::init_absorbing_walls(const PartSettings& settings) {
  const Index n = f_.size();
  Real mass = 0, radius = 0;
  for (Index i = 0; i < n; ++i) {
    mass += m_[i];
    radius += r_[i];
  }
  const Real grains = static_cast<Real>(std::max<Index>(n, 1));
  const Real rho = cfg_.absorbing_density_kg_m3 > 0 ? cfg_.absorbing_density_kg_m3
                                                    : mass / parts::bed_volume<D>(settings.part);
  Real cp = cfg_.absorbing_p_wave_speed_m_s;
  if (!(cp > 0)) {
    // The law's estimate from the mean grain (linear_spring: a chain of it).
    const std::optional<Real> estimate = std::visit(
        [&]<class Law>(const LawPair<Law>& /*laws*/) {
          return Law::p_wave_speed(cfg_, MeanGrain{radius / grains, mass / grains});
        },
        laws_);
    if (!estimate) throw std::logic_error("absorbing walls: the contact law needs a P-wave speed");
    cp = *estimate;
  }
  const Real nu = settings.grain.poisson_ratio;
  const Real cs = cfg_.absorbing_s_wave_speed_m_s > 0 ? cfg_.absorbing_s_wave_speed_m_s
                                                      : cp * std::sqrt((1 - 2 * nu) / (2 - 2 * nu));
  absorbing_ = AbsorbingWallParams{.normal_impedance = rho * cp, .tangential_impedance = rho * cs};
  step_at_ = -1;  // the walls' dashpots limit the step
  add_diagnostic("absorbing_wall_density_kg_m3", rho);
  add_diagnostic("absorbing_wall_p_wave_speed_m_s", cp);
  add_diagnostic("absorbing_wall_s_wave_speed_m_s", cs);
  // Each face's top: the highest centre among the grains it touches now (all grains' if it
  // touches none; no top without gravity). t = 0 here also on a restart: the part is built
  // from the initial grains before the checkpoint's fields replace them.
  const Real g_norm = gravity_.norm();
  const auto height = [&](Index i) {
    return g_norm > 0 ? Real(-x_[i].dot(gravity_) / g_norm) : Real(0);
  };
  const Real lowest = -std::numeric_limits<Real>::infinity();
  absorbing_top_.assign(cfg_.absorbing_walls.size(), lowest);
  Real top_all = lowest;
  for (Index i = 0; i < n; ++i)
    top_all = std::max(top_all, height(i));
  std::visit(
      [&]<class Law>(const LawPair<Law>& laws) {
        for (Index i = 0; i < n; ++i)
          for (std::size_t k = 0; k < cfg_.absorbing_walls.size(); ++k) {
            const WallPlane w = wall_plane(cfg_.absorbing_walls[k]);
            Vec<D> foot = x_[i];
            foot[w.axis] = w.plane;
            const ContactGeometry<D> g = sphere_wall_geometry<D>(x_[i], r_[i], foot);
            if (!g.touching()) continue;
            absorbing_top_[k] = std::max(absorbing_top_[k], height(i));
            const ContactForce<D> cf =
                evaluate_contact<D, Law>(laws.wall, g, RelativeVelocity<D>{}, m_[i],
                                         row_pitch(r_[i], r_[i]), Vec<D>::Zero(), Real(0));
            static_reaction_[i][w.axis] = std::max(cf.normal_force, Real(0));
          }
      },
      laws_);
  for (Real& top : absorbing_top_) {
    if (!(g_norm > 0))
      top = std::numeric_limits<Real>::infinity();
    else if (top == lowest)
      top = top_all;
  }
}

// Safeguard: a grain driven through a wall (its centre beyond the face: an overlap of more
// than its radius, which a blast can force against a Hertz wall) is put back, mirrored in the
// face, with its normal velocity reversed and scaled by the wall's restitution; the kinetic
// energy lost is booked as contact dissipation. Counted in wall_reflections. advance calls it
// for the grains outside the guard box (inside_guard).
template <int D>
void DemPart<D>::reflect_at_walls(Index i, Real& count, Real& lost) {
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

#define CRATER_DEM_WALLS(D)                                              \
  template void DemPart<D>::init_walls(bool);                            \
  template void DemPart<D>::place_walls();                               \
  template Real DemPart<D>::wall_area(int) const;                        \
  template void DemPart<D>::move_walls(Real, Real);                      \
  template void DemPart<D>::measure_walls();                             \
  template void DemPart<D>::set_wall_planes();                           \
  template std::vector<std::string> DemPart<D>::history_columns() const; \
  template std::vector<Real> DemPart<D>::history_values() const;         \
  template void DemPart<D>::init_absorbing_walls(const PartSettings&);   \
  template void DemPart<D>::reflect_at_walls(Index, Real&, Real&);
CRATER_DEM_WALLS(2)
CRATER_DEM_WALLS(3)
#undef CRATER_DEM_WALLS

}  // namespace crater::dem::detail
