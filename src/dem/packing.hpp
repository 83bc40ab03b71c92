// Packing of a DEM part's grains ([parts.packing], docs/theory.md "Packing"):
//   - the radii that fill a solids volume (1 - n) V_region, uniform in radius or from a
//     grading (sieve) curve given as mass fraction passing;
//   - random sequential addition: grains placed one by one, largest first, at uniformly random
//     positions that overlap no grain already placed; a column that cannot hold them all is
//     extended against gravity (the settled bed then comes down to about the target porosity);
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "dem/laws/contact_geometry.hpp"
#include "dem/settings.hpp"
#include "parts/region.hpp"

namespace crater::dem {

template <int D>
struct Grain {
  Vec<D> x;
  Real r = 0;
};

/// The contacts of a packing's grains as a DEM part keeps them between neighbour-list
/// rebuilds: per grain, in id order, `slots` entries of partner (another grain's id, -1 - face
/// for a wall; kNoPartner past the last), tangential spring [m] and rolling moment [N m] (empty
/// without rolling resistance). A settled packing carries them, so that a run starts from the
/// settled state itself, friction and all.
template <int D>
struct ContactHistory {
  static constexpr std::int64_t kNoPartner = std::numeric_limits<std::int64_t>::min();
  int slots = 0;
  std::vector<std::int64_t> partner;
  std::vector<Vec<D>> xi;
  std::vector<AngularVec<D>> roll;
};

/// A settled packing: its grains (in id order) and their contacts.
template <int D>
struct SettledPacking {
  std::vector<Grain<D>> grains;
  ContactHistory<D> contacts;
};

/// Volume of a grain: disk area (per metre of depth) in 2D, sphere volume in 3D.
template <int D>
Real grain_volume(Real r);

/// Radii whose grain volumes sum to `solid_volume` (to within half the last grain), drawn with
/// `seed`: from the sieve curve of `packing` if it has one, else uniform in [r_min, r_max].
/// Throws InputError (key `key`) if that takes more than `max_grains` grains.
template <int D>
std::vector<Real> draw_radii(const PackingSettings& packing, Real r_min, Real r_max,
                             Real solid_volume, std::uint64_t seed, std::size_t max_grains,
                             const SourceLocation& where, const std::string& key);

/// Random sequential addition of grains of the given radii (placed largest first) inside
/// `region`, extended against `gravity` up to the domain's face when they do not fit. Throws
/// InputError when even the tallest column cannot hold them.
template <int D>
std::vector<Grain<D>> random_packing(const parts::RegionConfig& region, std::vector<Real> radii,
                                     const Vec<D>& gravity, const Vec<D>& domain_lo,
                                     const Vec<D>& domain_hi, std::uint64_t seed,
                                     const SourceLocation& where, const std::string& key);

/// Volume of the region (area in 2D).
template <int D>
Real region_volume(const parts::RegionConfig& region);

}  // namespace crater::dem
