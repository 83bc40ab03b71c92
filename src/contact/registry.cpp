// The pairings by the kinds of their two parts; see registry.hpp.
#include "contact/registry.hpp"

#include <array>
#include <stdexcept>
#include <string>

#include "contact/particle_particle.hpp"
#include "contact/particle_surface.hpp"
#include "contact/surface_surface.hpp"

namespace crater::contact {
namespace {

template <int D>
using Factory = std::unique_ptr<Pairing<D>> (*)(const ContactSettings&, std::size_t points,
                                                std::size_t other, const PartList<D>&);

/// A pairing serves a contact between a part of kind `points` and one of kind `other`, in
/// either order in the scenario; the factory gets the first's index as `points`.
template <int D>
struct Entry {
  PartKind points;
  PartKind other;
  Factory<D> make;
};

template <int D>
constexpr std::array<Entry<D>, 4> kPairings{{
    {PartKind::Particles, PartKind::Surface, &make_pairing_of<ParticleSurface<D>, D>},  // sph-fem
    {PartKind::RotatingParticles, PartKind::Surface,
     &make_pairing_of<ParticleSurface<D>, D>},                                       // dem-fem
    {PartKind::Surface, PartKind::Surface, &make_pairing_of<SurfaceSurface<D>, D>},  // fem-fem
    {PartKind::Particles, PartKind::RotatingParticles,
     &make_pairing_of<ParticleParticle<D>, D>},  // sph-dem
}};

}  // namespace

template <int D>
PartKind kind_of(const parts::Part<D>& part) {
  if (part.contact_surface()) return PartKind::Surface;
  if (const auto pts = part.contact_points())
    return pts->angular_velocity ? PartKind::RotatingParticles : PartKind::Particles;
  throw std::logic_error("part '" + part.name() + "' offers nothing to contacts");
}

template <int D>
std::unique_ptr<Pairing<D>> make_pairing(const ContactSettings& settings,
                                         const PartList<D>& parts) {
  const std::size_t first = settings.parts[0], second = settings.parts[1];
  const PartKind k0 = kind_of(*parts[first]), k1 = kind_of(*parts[second]);
  for (const Entry<D>& e : kPairings<D>) {
    if (e.points == k0 && e.other == k1) return e.make(settings, first, second, parts);
    if (e.points == k1 && e.other == k0) return e.make(settings, second, first, parts);
  }
  throw std::logic_error("no contact pairing joins '" + parts[first]->name() + "' and '" +
                         parts[second]->name() + "'");
}

template PartKind kind_of<2>(const parts::Part<2>&);
template PartKind kind_of<3>(const parts::Part<3>&);
template std::unique_ptr<Pairing<2>> make_pairing<2>(const ContactSettings&, const PartList<2>&);
template std::unique_ptr<Pairing<3>> make_pairing<3>(const ContactSettings&, const PartList<3>&);

}  // namespace crater::contact
