// A dense random packing of polydisperse disks by geometric deposition: each grain is put at
// the lowest place where it rests on two supports (grains, the region's faces, the bodies it
// must keep clear of), overlapping nothing. Grains are drawn uniformly in [r_min, r_max] and
// placed in the order drawn; a grain that fits nowhere near the lowest grain still open
// closes that grain and tries the next one. It is a constructive method in the family of
// [FHO03] and [BAG05] (theirs grow a front from a seed; this one grows it from the floor, as
// sand is poured), so it needs no dynamics and costs O(N) with a cell grid; a short
// relaxation under gravity then loads the contacts (docs/theory.md, "Dense packing").
//
// The result depends only on its inputs (one thread, one order of placing): the same bed on
// any machine with this binary.
//
// References
//   [FHO03] Y. T. Feng, K. Han, D. R. J. Owen, "Filling domains with disks: an advancing front
//           approach", Int. J. Numer. Meth. Engng 56 (2003) 699-713.
//   [BAG05] K. Bagi, "An algorithm to generate random dense arrangements for discrete element
//           simulations of granular assemblies", Granular Matter 7 (2005) 31-43.
#pragma once

#include <cstdint>
#include <vector>

#include "core/types.hpp"
#include "dem/packing.hpp"
#include "parts/region.hpp"

namespace crater::dem {

/// Changes whenever the algorithm would lay another bed from the same input (cache keys).
inline constexpr int kDensePackingVersion = 1;

/// What the packing is asked for. `lo`, `hi`: the box the grains fill (each grain wholly
/// inside); `up_axis`, `up_sign`: which way is up (against gravity; the floor is the face
/// below); `keep_clear`: regions no grain may overlap (boxes, disks).
template <int D>
struct DensePackingInput {
  Vec<D> lo = Vec<D>::Zero(), hi = Vec<D>::Zero();
  int up_axis = D - 1;
  Real up_sign = 1;
  Real r_min = 0, r_max = 0;
  std::uint64_t seed = 0;
  std::vector<parts::RegionConfig> keep_clear;
  std::size_t max_grains = 50'000'000;
};

/// How the packing went (for the log and `crater check`).
struct DensePackingReport {
  std::size_t grains = 0;
  Real solid_volume = 0;       // sum of the grains' volumes [m^2 per m in 2D, m^3 in 3D]
  Real free_volume = 0;        // the box less the regions kept clear
  std::size_t reopened = 0;    // passes that reopened every grain once the open ones ran out
  std::size_t new_floors = 0;  // grains started on the faces and bodies alone (no grain below)
};

/// The grains, in the order placed: disks (2D) or spheres (3D, dense_packing_spheres.cpp).
/// Throws std::invalid_argument for r_min <= 0 or r_max < r_min, or for a box thinner than a
/// grain, and std::length_error past max_grains.
template <int D>
std::vector<Grain<D>> dense_packing(const DensePackingInput<D>& in, DensePackingReport* report);

namespace detail {
/// The 3D deposition (dense_packing_spheres.cpp).
std::vector<Grain<3>> deposit_spheres(const DensePackingInput<3>& in, DensePackingReport& report);
}  // namespace detail

}  // namespace crater::dem
