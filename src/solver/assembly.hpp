// Assembly: the one place that reads the whole scenario to build what the time loop drives.
// Each part gets its method's own settings (sph/, dem/, fem/ settings.hpp) made from the
// Config here, so no method sees the scenario as a whole; packed DEM parts take their grains
// from the settled-packing cache (packing_cache.hpp) or settle them and fill it.
#pragma once

#include <memory>
#include <vector>

#include "contact/settings.hpp"
#include "dem/settings.hpp"
#include "fem/settings.hpp"
#include "io/scenario/config.hpp"
#include "parts/setup.hpp"
#include "solver/part_names.hpp"
#include "sph/settings.hpp"

namespace crater::solver {

/// What every part is built from, whatever its method (domain, region, initial state, zones,
/// the regions it is carved by, detonation points).
parts::PartSetup part_setup(const io::Config& config, const io::PartConfig& part);

sph::PartSettings sph_settings(const io::Config& config, const io::PartConfig& part);
dem::PartSettings dem_settings(const io::Config& config, const io::PartConfig& part);
fem::PartSettings fem_settings(const io::Config& config, const io::PartConfig& part);

/// The scenario's contacts as contact/ takes them; per part E = 2 G (1 + nu) of its granular
/// material (0 for other materials), the stiffness of particle-particle contacts.
std::vector<contact::ContactSettings> contact_settings(const io::Config& config);

/// Whether a DEM part whose packing is to be settled and is not in the cache is settled now
/// (a run) or built as laid (crater check: the same grains, so the same solid fraction and
/// stable step, without the settling's minutes).
enum class Settling { Now, CachedOnly };

/// The scenario's parts, in its order.
template <int D>
std::vector<std::unique_ptr<Part<D>>> build_parts(const io::Config& config,
                                                  Settling settling = Settling::Now);

}  // namespace crater::solver
