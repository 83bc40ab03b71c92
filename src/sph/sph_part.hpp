// An SPH part: a body of fluid (detonation products, gas, water) discretised by particles
// (paper section II-B). Per particle: position, velocity, mass, density (continuity, eq. 32),
// specific internal energy (energy equation), pressure from the part's EOS.
#pragma once

#include <memory>

#include "parts/part.hpp"
#include "sph/settings.hpp"

namespace crater::sph {

/// Builds the SPH part `settings` describe (particles on a lattice filling its region).
template <int D>
std::unique_ptr<parts::Part<D>> make_sph_part(const PartSettings& settings);

}  // namespace crater::sph
