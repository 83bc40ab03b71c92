// The geometry behind the 3D probes (probes.hpp): the ground surface averaged in rings about
// the crater's axis, the crater's depth and radius read off that profile, and the part of a
// plate's undeformed footprint that no live element covers (perforation). Pure functions of
// arrays, so that they are tested on their own (tests/unit/solver/test_probe_geometry.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "core/types.hpp"

namespace crater::solver {

/// One ring of the axisymmetric surface profile: the columns whose centres lie at a distance
/// r from the axis with j w <= r < (j + 1) w (w the ring width).
struct Ring {
  Real r_m = 0;         // mean distance of its columns' centres from the axis
  Real surface0_m = 0;  // mean surface height at t = 0
  Real surface_m = 0;   // mean surface height now
  Real drop_m() const { return surface0_m - surface_m; }
};

/// Rings of width `width_m` about the axis, outward, from columns at distances `r_m` (from the
/// axis) with surfaces `surface0_m` (t = 0) and `surface_m` (now): each ring the mean over its
/// columns with a finite surface at both times; rings with none are left out.
std::vector<Ring> ring_profile(const std::vector<Real>& r_m, const std::vector<Real>& surface0_m,
                               const std::vector<Real>& surface_m, Real width_m);

struct CraterSize {
  Real depth_m = 0;   // the largest drop of the rings; 0 when it is not above the threshold
  Real radius_m = 0;  // where the drop falls below the threshold, outward; 0 without a crater
  bool reaches_end = false;  // the drop never falls below it: radius_m is the last ring's, a
                             // lower bound set by the profile's (the domain's) extent
};

/// The crater of a ring profile (rings outward). Its depth is the largest drop of a ring, a
/// crater only when that exceeds `threshold_m` (the largest grain radius: less is the
/// packing's own roughness). Its radius: going outward from the deepest ring (the axis ring of
/// a bowl), the radius at which the drop first falls below the threshold, linear between the
/// rings' radii; the last ring's radius when it never does (the crater reaches the profile's
/// end: a lower bound).
CraterSize crater_of_profile(const std::vector<Ring>& rings, Real threshold_m);

/// A finite-element plate's elements as the writers list them (parts::Geometry): nodes'
/// reference (undeformed) positions, connectivity with end offsets, and which are eroded.
template <int D>
struct PlateCells {
  const std::vector<Vec<D>>& reference;
  const std::vector<std::int64_t>& connectivity;
  const std::vector<std::int64_t>& offsets;
  const std::vector<std::uint8_t>& eroded;
};

/// The area (3D, m^2) or length (2D, m) of the plate's undeformed horizontal footprint that no
/// live element covers: elements whose reference nodes project onto the same horizontal points
/// form a column through the thickness (a structured or extruded mesh), and the footprints of
/// the columns all of whose elements are eroded are summed, each the convex hull of its
/// projected nodes (2D: their x extent). The vertical axis is the last one. An element that
/// shares its footprint with no other is a column of its own (an unstructured mesh: an
/// approximation).
template <int D>
Real perforated_footprint(const PlateCells<D>& plate);

}  // namespace crater::solver
