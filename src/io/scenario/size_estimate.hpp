// The size of each part estimated when the scenario is loaded, without building it: lattice
// sites of its region at its spacing (zones with their own spacing counted at theirs, carved
// regions left out), grains of a random packing (solid volume / mean grain volume), grains
// placed by hand, or elements of its FEM mesh. With the key that sets the count, so that the
// memory check (solver/memory_estimate.hpp) can refuse a scenario before anything is allocated.
#pragma once

#include <toml++/toml.h>

#include "io/scenario/config.hpp"

namespace crater::io {

/// Fills estimated_count, resolution_key and resolution_where of every part of `c`; `root` is
/// the validated document the parts were read from (for the keys' lines).
void estimate_part_sizes(const toml::table& root, Config& c);

/// Volume of a region [m^dim] (2D: area, per metre of depth).
Real region_volume(const RegionConfig& r, int dim);

/// Volume region `a` shares with region `b` [m^dim]: exact for two boxes; a disk or sphere
/// counts its volume times the fraction of its bounding box inside the other's bounding box.
Real shared_volume(const RegionConfig& a, const RegionConfig& b, int dim);

/// Mean volume of a grain whose radius is uniform in [r_min, r_max] [m^dim]:
/// 2D \pi (a^2 + a b + b^2) / 3, 3D \pi (a + b)(a^2 + b^2) / 3.
Real mean_grain_volume(Real r_min, Real r_max, int dim);

/// Lattice sites of a sph or dem part: region volume / spacing^dim, zones at their spacing,
/// carved parts' regions left out.
Real lattice_sites(const Config& c, const PartConfig& p);

/// Grains of a random packing: (1 - porosity) x region volume / mean grain volume, per band of
/// the sieve curve when there is one, less the carved fraction of the region.
Real packed_grains(const Config& c, const PartConfig& p);
/// Grains of a dense packing (packing.method = "dense"): 0.85 of the free volume over the mean
/// grain's volume (an upper bound: the beds reach about 0.82).
Real dense_grains(const Config& c, const PartConfig& p);

/// Elements of an fem part: of its Gmsh mesh, or of the structured mesh of its box.
Real fem_elements(const Config& c, const PartConfig& p);

}  // namespace crater::io
