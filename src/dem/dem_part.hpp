// A DEM part: grains (disks in 2D, per metre of depth; spheres in 3D) with rotation, contact
// laws from src/dem/laws, rigid and absorbing (viscous) walls on domain faces, gravity and
// Cundall local damping (paper section II-A).
#pragma once

#include <memory>

#include "io/scenario/config.hpp"
#include "parts/part.hpp"

namespace crater::dem {

/// Builds the DEM part described by `part`: grains on the region's lattice (radii drawn from
/// the part's seed) or placed one by one.
template <int D>
std::unique_ptr<parts::Part<D>> make_dem_part(const io::Config& config, const io::PartConfig& part);

}  // namespace crater::dem
