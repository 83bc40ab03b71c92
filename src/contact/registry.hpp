// Which pairing serves a contact, decided from what its two parts offer (parts/part.hpp):
// particles (contact_points), rotating particles (contact_points with an angular velocity:
// grains) or a surface (contact_surface). A new pairing is its own file and one line in
// registry.cpp's table.
#pragma once

#include <memory>

#include "contact/pairing.hpp"
#include "contact/settings.hpp"

namespace crater::contact {

/// What a part offers to contacts.
enum class PartKind { Particles, RotatingParticles, Surface };

/// The kind of `part` from its state views; throws std::logic_error when it offers none.
template <int D>
PartKind kind_of(const parts::Part<D>& part);

/// Builds the pairing of `settings.parts` from the table; throws std::logic_error for a pair
/// of kinds no pairing serves (the scenario's validation refuses those before).
template <int D>
std::unique_ptr<Pairing<D>> make_pairing(const ContactSettings& settings, const PartList<D>& parts);

}  // namespace crater::contact
