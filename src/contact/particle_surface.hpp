// Particles (SPH or DEM) against the surface of a solid (FEM): each particle against the face
// of its largest overlap, with the offset of penetrations found at first touch; coupling.hpp's
// header comment has the rules and equations.
#pragma once

#include <vector>

#include "contact/face_search.hpp"
#include "contact/pairing.hpp"

namespace crater::contact {

template <int D>
class ParticleSurface final : public Pairing<D> {
 public:
  /// `points` offers contact_points(), `other` contact_surface().
  using Pairing<D>::Pairing;

  void limit_step(const PartList<D>& parts, PairLimits& limits) const override;
  void apply(const PartList<D>& parts, Real dt_s, ContactForces<D>& out) override;

 private:
  using Hit = FaceHit<D>;
  void add_load(const parts::ContactSurface<D>& surf, const Hit& h) const;
  // Fills the spring sums from the current state (without changing it).
  void measure_load(const PartList<D>& parts) const;

  mutable NearCandidates<D> kept_;  // the candidate faces, kept between steps by grain id
};

}  // namespace crater::contact
