// What a part of any method is built from, as the scenario reader hands it over: the domain it
// lives in, its region and lattice pitch, how it starts (initial state, zones), the regions of
// other parts it leaves empty and its detonation points. Each method adds its own settings
// (sph/settings.hpp, dem/settings.hpp, fem/settings.hpp); the solver's assembly puts the two
// together, so no method sees the scenario as a whole.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "parts/region.hpp"

namespace crater::parts {

/// Faces of the domain box, for walls: 2*axis + (0 = min side, 1 = max side).
enum class Face { Left = 0, Right = 1, Bottom = 2, Top = 3, Back = 4, Front = 5 };

/// The points on a face of their bounding box (within 1e-9 of its largest extent), ascending:
/// an FEM part's face from its reference positions (boundaries, loads, face gauges).
template <int D>
std::vector<Index> points_on_face(const std::vector<Vec<D>>& x, Face face) {
  const int axis = static_cast<int>(face) / 2;
  const bool upper = static_cast<int>(face) % 2 == 1;
  Vec<D> lo = Vec<D>::Constant(std::numeric_limits<Real>::infinity()), hi = -lo;
  for (const Vec<D>& p : x) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Real plane = upper ? hi[axis] : lo[axis];
  const Real tol = 1e-9 * (hi - lo).maxCoeff();
  std::vector<Index> out;
  for (std::size_t k = 0; k < x.size(); ++k)
    if (std::abs(x[k][axis] - plane) <= tol) out.push_back(static_cast<Index>(k));
  return out;
}

/// What happens to a particle (SPH or DEM) that leaves the domain box: the run stops (exit 3),
/// or the particle is removed at the end of the step and booked as having left.
enum class Outflow { Stop, Remove };

struct Domain {
  // min_m and max_m were given; an FEM-only scenario may leave them (and [domain]) out, and
  // then the box is unbounded (infinite corners; nothing that needs a box is allowed).
  bool bounded = true;
  Vec3 min_m{};
  Vec3 max_m{};
  Vec3 gravity_m_s2{};
  Outflow outflow = Outflow::Stop;
  // DEM grains that leave are removed in batches, this many steps after the first went out
  // (and at frames); 1 (the default): at the end of the step they left in.
  std::int64_t outflow_batch_steps = 1;
  // Faces that are planes of symmetry for every part ([domain] symmetry_planes): SPH mirror
  // images, DEM frictionless walls without rolling resistance, FEM nodes on the plane held
  // normal to it. A quarter model is two of them.
  std::vector<Face> symmetry_planes;
  // On several MPI ranks, what the particle parts' cuts weigh when they are made again
  // ([domain] balance, fields/balance.hpp): each rank's measured time, or the cost model.
  bool balance_by_time = true;
};

/// Whether `face` is one of the domain's planes of symmetry.
inline bool is_symmetry_plane(const Domain& d, Face face) {
  for (const Face f : d.symmetry_planes)
    if (f == face) return true;
  return false;
}

/// The coordinate [m] of a face of the domain box on its axis.
inline Real face_coordinate(const Domain& d, Face face) {
  const int axis = static_cast<int>(face) / 2;
  return static_cast<int>(face) % 2 ? d.max_m[axis] : d.min_m[axis];
}

/// The domain's planes of symmetry as cuts of a particle lattice (region_lattice).
inline std::vector<LatticeCut> lattice_cuts(const Domain& d) {
  std::vector<LatticeCut> cuts;
  for (const Face f : d.symmetry_planes)
    cuts.push_back({static_cast<int>(f) / 2, face_coordinate(d, f), static_cast<int>(f) % 2 == 1});
  return cuts;
}

struct InitialState {
  std::optional<Real> density_kg_m3;
  std::optional<Real> pressure_pa;
  Vec3 velocity_m_s{};
};

/// A sub-region with its own initial state; unset values fall back to the part's.
struct Zone {
  RegionConfig region;
  std::optional<Real> spacing_m;  // own lattice pitch (unset: the part's lattice)
  std::optional<Real> density_kg_m3;
  std::optional<Real> pressure_pa;
  std::optional<Vec3> velocity_m_s;
};

// Where a charge is lit: at a point, over a plane (a plane-wave lens: the front starts from the
// whole plane) or along a line (a detonating cord; in 2D a line and a plane are the same). A
// particle lights at time_s + (its distance to it) / D.
enum class Initiator { Point, Plane, Line };

struct DetonationPoint {
  Initiator shape = Initiator::Point;
  Vec3 point_m{};
  Vec3 axis{};  // a plane's unit normal, a line's unit direction
  Real time_s = 0;
};

/// The method-independent description of one part.
struct PartSetup {
  std::string name;
  Domain domain;
  Real spacing_m = 0;
  RegionConfig region;
  InitialState initial;
  std::vector<Zone> zones;
  std::vector<RegionConfig> carving;  // regions of other parts this part's particles leave empty
  std::vector<DetonationPoint> detonations;
  SourceLocation where;  // of the part in the scenario, for errors found while building it
};

/// The volume a part's particles fill: its region's, less what the parts it is carved around
/// take from it (a box region; other regions are not carved by volume here).
template <int D>
Real bed_volume(const PartSetup& part) {
  Real v = region_volume_of<D>(part.region);
  if (part.region.type == RegionType::Box) v -= carved_volume<D>(part.region, part.carving);
  return v;
}

}  // namespace crater::parts
