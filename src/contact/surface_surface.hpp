// The surfaces of two solids (FEM-FEM): penalty node-to-segment, both ways; coupling.hpp's
// header comment has the rules and equations.
#pragma once

#include <memory>
#include <vector>

#include "contact/face_geometry.hpp"
#include "contact/pairing.hpp"

namespace crater::contact {

template <int D>
class SurfaceSurface final : public Pairing<D> {
 public:
  /// Both parts offer contact_surface().
  SurfaceSurface(const ContactSettings& settings, std::size_t points, std::size_t other,
                 const PartList<D>& parts)
      : Pairing<D>(settings, points, other, parts) {}

  void limit_step(const PartList<D>& parts, StepSearch& search) const override;
  void apply(const PartList<D>& parts, Real dt_s, ContactForces<D>& out) override;

  /// A surface node against a face of the other part (face < 0: none).
  struct NodeHit {
    Index node = -1;
    Index face = -1;
    FacePoint<D> where;
    Vec<D> n = Vec<D>::Zero();  // the face's outward normal
    Real overlap = 0;           // depth behind the face
    Real k = 0;                 // penalty stiffness (without the scale)
  };
  /// Every surface node of `nodes_of` that carries mass, ascending, with the face of
  /// `faces_of` it is in contact with.
  static std::vector<NodeHit> node_hits(const parts::ContactSurface<D>& nodes_of,
                                        const parts::ContactSurface<D>& faces_of);

 private:
  using Pairing<D>::settings_;
  using Pairing<D>::points_;
  using Pairing<D>::other_;
  using Pairing<D>::name_;
  using Pairing<D>::last_;
  using Pairing<D>::load_;

  // One side of a direction: its surface, spring sums and forces (null: sums only).
  struct Side {
    const parts::ContactSurface<D>& surface;
    std::vector<Real>& load;
    std::vector<Vec<D>>* force;  // null: loads only
  };
  // The spring sums and forces of one direction, the nodes of `a` against the faces of `b`.
  // Returns the contact's diagnostics of this direction, force_on_other = sign x the sum of
  // the forces on a's nodes.
  ContactSums<D> node_surface(const Side& a, const Side& b, const std::vector<NodeHit>& hits,
                              Real sign) const;
  void measure_load(const PartList<D>& parts) const;
};

template <int D>
std::unique_ptr<Pairing<D>> make_surface_surface(const ContactSettings& settings,
                                                 std::size_t points, std::size_t other,
                                                 const PartList<D>& parts) {
  return std::make_unique<SurfaceSurface<D>>(settings, points, other, parts);
}

}  // namespace crater::contact
