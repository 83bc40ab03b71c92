// A DEM part: grains (disks in 2D, per metre of depth; spheres in 3D) with rotation, contact
// laws from src/dem/laws, rigid and absorbing (viscous) walls on domain faces, gravity and
// Cundall local damping (paper section II-A).
//
// A packed part ([parts.packing]) is built in steps the solver's assembly takes: the grains
// of a random packing (random_grains), settled under gravity (settle_grains), then the part
// from them (make_dem_part). Between the steps the assembly keeps settled packings in a file
// cache keyed by packing_key_text; this folder reads and writes no files.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "dem/dense_packing.hpp"
#include "dem/packing.hpp"
#include "dem/settings.hpp"
#include "parts/part.hpp"

namespace crater::dem {

/// How a packed part's grains were obtained (its diagnostics packing_reused, settle_time_s,
/// settle_steps).
struct PackingReport {
  bool reused = false;     // read from the cache
  bool unsettled = false;  // settle asked for, but the part was built as laid (crater check)
  Real settle_time_s = 0;
  long long settle_steps = 0;
};

/// Builds the DEM part `settings` describe, from `grains` if given (a packing), else from the
/// grains placed by hand, else one per lattice site of its region (radii from its seed).
/// `contacts`, when given, are the grains' contact histories (a settled packing's).
template <int D>
std::unique_ptr<parts::Part<D>> make_dem_part(const PartSettings& settings,
                                              const std::vector<Grain<D>>* grains = nullptr,
                                              const PackingReport& report = {},
                                              const ContactHistory<D>* contacts = nullptr);

/// Everything that shapes the part's settled packing, as text (hex floats: exact); a hash of it
/// keys the packing cache.
template <int D>
std::string packing_key_text(const PartSettings& settings);

/// The grains of the part's random packing (packing.random): radii for the target porosity,
/// placed by random sequential addition (packing.hpp).
template <int D>
std::vector<Grain<D>> random_grains(const PartSettings& settings);

/// The grains of the part's dense packing (packing.method = "dense", dense_packing.hpp): its
/// box region filled by geometric deposition around the regions it is carved around. Throws
/// InputError for a region that is not a box, gravity not along one axis, or grains that do
/// not fit.
template <int D>
std::vector<Grain<D>> dense_grains(const PartSettings& settings, DensePackingReport& report);

/// The part alone under gravity, with its walls (absorbing faces rigid), the regions it is
/// carved around as fixed bodies, and the settling damping, from `grains` (nullptr: the part's own
/// lattice or placed grains), until the grains have had the time to fall the column's height and
/// their mean kinetic energy is below settle_kinetic_ratio x m g r. Returns the grains at rest
/// with their contacts (less those with the fixed bodies); throws InputError if a grain fails
/// or they do not settle within settle_max_time_s. `spread` (several ranks, every one calling
/// with the same grains): the bed is spread over them while it settles, with one rank's bits,
/// and the settled grains come back whole on the root alone (empty elsewhere).
template <int D>
SettledPacking<D> settle_grains(const PartSettings& settings, const std::vector<Grain<D>>* grains,
                                PackingReport& report, const parallel::Comm* spread = nullptr);

}  // namespace crater::dem
