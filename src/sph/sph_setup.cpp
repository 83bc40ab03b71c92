// An SPH part's particles before the first step; see sph_setup.hpp.
#include "sph/sph_setup.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "parts/region.hpp"

namespace crater::sph {

using parts::to_vec;

template <int D>
ParticleLattice<D> particle_lattice(const parts::PartSetup& pc, Real spacing) {
  ParticleLattice<D> out;
  auto owner = [&](const Vec<D>& x) {  // index of the last spacing zone holding x, or -1
    int k = -1;
    for (std::size_t z = 0; z < pc.zones.size(); ++z)
      if (pc.zones[z].spacing_m && parts::region_contains<D>(pc.zones[z].region, x))
        k = static_cast<int>(z);
    return k;
  };
  const std::vector<parts::LatticeCut> cuts = parts::lattice_cuts(pc.domain);
  for (const auto& x : parts::region_lattice<D>(pc.region, spacing, cuts))
    if (owner(x) < 0 && !parts::carved<D>(pc.carving, x, 0.5 * spacing))
      out.x.push_back(x), out.pitch.push_back(spacing);
  for (std::size_t z = 0; z < pc.zones.size(); ++z) {
    if (!pc.zones[z].spacing_m) continue;
    for (const auto& x : parts::region_lattice<D>(pc.zones[z].region, *pc.zones[z].spacing_m, cuts))
      if (parts::region_contains<D>(pc.region, x) && owner(x) == static_cast<int>(z))
        out.x.push_back(x), out.pitch.push_back(*pc.zones[z].spacing_m);
  }
  return out;
}

template <int D>
StartState<D> start_state(const parts::PartSetup& pc, Real rho0, const Vec<D>& x) {
  StartState<D> s;
  s.rho = pc.initial.density_kg_m3.value_or(rho0);
  s.pressure = pc.initial.pressure_pa;
  s.v = to_vec<D>(pc.initial.velocity_m_s);
  for (const auto& z : pc.zones) {
    if (!parts::region_contains<D>(z.region, x)) continue;
    if (z.density_kg_m3) s.rho = *z.density_kg_m3;
    if (z.pressure_pa) s.pressure = z.pressure_pa;
    if (z.velocity_m_s) s.v = to_vec<D>(*z.velocity_m_s);
  }
  return s;
}

template <int D>
Real lighting_time(const parts::PartSetup& pc, bool explosive, Real d_cj, const Vec<D>& x) {
  Real tl = explosive && !pc.detonations.empty() ? std::numeric_limits<Real>::infinity() : 0;
  for (const auto& dp : pc.detonations) {
    const Vec<D> r = x - to_vec<D>(dp.point_m);
    const Vec<D> a = to_vec<D>(dp.axis);
    const Real distance = dp.shape == parts::Initiator::Point   ? r.norm()
                          : dp.shape == parts::Initiator::Plane ? std::abs(r.dot(a))
                                                                : (r - r.dot(a) * a).norm();
    tl = std::min(tl, dp.time_s + distance / d_cj);
  }
  return tl;
}

template ParticleLattice<2> particle_lattice<2>(const parts::PartSetup&, Real);
template ParticleLattice<3> particle_lattice<3>(const parts::PartSetup&, Real);
template StartState<2> start_state<2>(const parts::PartSetup&, Real, const Vec<2>&);
template StartState<3> start_state<3>(const parts::PartSetup&, Real, const Vec<3>&);
template Real lighting_time<2>(const parts::PartSetup&, bool, Real, const Vec<2>&);
template Real lighting_time<3>(const parts::PartSetup&, bool, Real, const Vec<3>&);

}  // namespace crater::sph
