// What a contact between two parts needs to know, as the solver hands it over (built from the
// scenario's [[contacts]] by src/solver/); contact/ reads no scenario itself. Which pairing
// serves a contact is decided from what the two parts offer (registry.hpp), not from here.
#pragma once

#include <array>
#include <cstddef>
#include <string>

#include "core/types.hpp"

namespace crater::contact {

struct ContactSettings {
  std::array<std::size_t, 2> parts{};  // indices into the solver's parts, in scenario order
  Real penalty_scale = 1.0;            // s_p of the penalty stiffness [-]
  Real friction = 0;                   // Coulomb coefficient mu between the two parts [-]
  Real damping_ratio = 0.1;            // xi, fraction of critical damping of the normal spring
  // Per part (as `parts`): Young's modulus E = 2 G (1 + nu) of its granular material [Pa], the
  // stiffness of particle-particle contacts against its grains; 0 when it has none.
  std::array<Real, 2> grain_modulus_pa{};
  // Per part (as `parts`): the group of its mesh file the contact is restricted to
  // (surface_filter.hpp); empty: its whole surface.
  std::array<std::string, 2> surface_group{};
};

}  // namespace crater::contact
