// Particles (SPH or DEM) against the surface of a solid (FEM): each particle against the face
// of its largest overlap, with the offset of penetrations found at first touch; coupling.hpp's
// header comment has the rules and equations.
#pragma once

#include <memory>
#include <vector>

#include "contact/face_geometry.hpp"
#include "contact/pairing.hpp"

namespace crater::contact {

template <int D>
class ParticleSurface final : public Pairing<D> {
 public:
  /// `points` offers contact_points(), `other` contact_surface().
  ParticleSurface(const ContactSettings& settings, std::size_t points, std::size_t other,
                  const PartList<D>& parts)
      : Pairing<D>(settings, points, other, parts) {}

  void limit_step(const PartList<D>& parts, StepSearch& search) const override;
  void apply(const PartList<D>& parts, Real dt_s, ContactForces<D>& out) override;

  /// A particle against a face: which particle and face, where, the normal, the overlap.
  struct Hit {
    Index particle = -1;
    Index face = -1;
    FacePoint<D> where;
    Vec<D> n = Vec<D>::Zero();  // contact normal, from the surface to the particle
    Real overlap = 0;
  };
  /// The particles that touch a face, ascending, each with its face of largest overlap (ties:
  /// the lowest face).
  static std::vector<Hit> hits(const parts::ContactPoints<D>& pts,
                               const parts::ContactSurface<D>& surf);

 private:
  using Pairing<D>::settings_;
  using Pairing<D>::points_;
  using Pairing<D>::other_;
  using Pairing<D>::name_;
  using Pairing<D>::last_;
  using Pairing<D>::load_;

  struct Push {
    Vec<D> force = Vec<D>::Zero();  // on the particle
    Real normal = 0;
  };
  /// The force of each hit (in parallel); keeps the particles' offsets.
  std::vector<Push> pushes(const std::vector<Hit>& hits, Real dt,
                           const parts::ContactPoints<D>& pts,
                           const parts::ContactSurface<D>& surf) const;
  Real stiffness(const parts::ContactSurface<D>& surf, Index face) const;
  void add_load(const parts::ContactSurface<D>& surf, const Hit& h) const;
  // Fills the spring sums from the current state (without changing it).
  void measure_load(const PartList<D>& parts) const;
};

template <int D>
std::unique_ptr<Pairing<D>> make_particle_surface(const ContactSettings& settings,
                                                  std::size_t points, std::size_t other,
                                                  const PartList<D>& parts) {
  return std::make_unique<ParticleSurface<D>>(settings, points, other, parts);
}

}  // namespace crater::contact
