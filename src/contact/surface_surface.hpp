// The surfaces of two solids (FEM-FEM): penalty node-to-segment, both ways; coupling.hpp's
// header comment has the rules and equations.
#pragma once

#include <vector>

#include "contact/face_search.hpp"
#include "contact/pairing.hpp"

namespace crater::contact {

template <int D>
class SurfaceSurface final : public Pairing<D> {
 public:
  /// Both parts offer contact_surface().
  using Pairing<D>::Pairing;

  void limit_step(const PartList<D>& parts, PairLimits& limits) const override;
  void apply(const PartList<D>& parts, Real dt_s, ContactForces<D>& out) override;

 private:
  void measure_load(const PartList<D>& parts) const;
};

}  // namespace crater::contact
