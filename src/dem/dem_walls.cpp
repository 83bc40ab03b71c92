// The DEM part's walls (dem_part_impl.hpp): the planes of the rigid and absorbing faces, the
// absorbing walls' impedance and static reactions, and the wall guard. The walls' forces on
// the grains are taken in the force stage (dem_pair_loop.cpp: rigid_wall_contacts,
// absorbing_wall_loads).
#include <Eigen/Geometry>  // cross products of 3D contact laws

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <variant>

#include "dem/dem_part_impl.hpp"

namespace crater::dem::detail {

// The planes of the rigid walls and of every face (the guard), the box beyond which a grain
// touches no rigid wall, and the walls' contact histories.
template <int D>
void DemPart<D>::init_walls() {
  const Index n = f_.size();
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
  add_diagnostic("absorbing_wall_density_kg_m3", rho);
  add_diagnostic("absorbing_wall_p_wave_speed_m_s", cp);
  add_diagnostic("absorbing_wall_s_wave_speed_m_s", cs);
  std::visit(
      [&]<class Law>(const LawPair<Law>& laws) {
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

#define CRATER_DEM_WALLS(D)                                            \
  template void DemPart<D>::init_walls();                              \
  template void DemPart<D>::init_absorbing_walls(const PartSettings&); \
  template void DemPart<D>::reflect_at_walls(Index, Real&, Real&);
CRATER_DEM_WALLS(2)
CRATER_DEM_WALLS(3)
#undef CRATER_DEM_WALLS

}  // namespace crater::dem::detail
