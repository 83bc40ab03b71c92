// The walls of an SPH part (sph_part.cpp): dummy wall particles behind no-slip walls (Adami, Hu
// & Adams 2012) and mirror images behind free-slip walls (Libersky et al. 1993), as laid out
// from the domain box; their states are set from the fluid's at each force stage
// (SphPart::wall_state, SphPart::ghost_state).
#pragma once

#include <span>
#include <vector>

#include "core/index.hpp"
#include "core/types.hpp"
#include "parallel/parallel.hpp"
#include "parts/setup.hpp"

namespace crater::sph {

/// Dummy wall particles behind the walled faces of the domain box, `layers` deep at pitch s
/// (Adami, Hu & Adams 2012, J. Comput. Phys. 231, 7057). A corner shared by faces of axes
/// a < b is laid by the face of axis a only (when both are walled), so no point is doubled.
template <int D>
struct WallLattice {
  std::vector<Vec<D>> x;
  // Per wall particle: -1 along each axis where it lies beyond a face of the domain, +1
  // elsewhere; a free-slip wall mirrors those velocity components (both at a corner).
  std::vector<Vec<D>> mirror;
};

template <int D>
WallLattice<D> wall_lattice(const parts::Domain& domain, const std::vector<parts::Face>& faces,
                            int layers, Real s);

/// Free-slip walls are planes of symmetry: each particle within `radius` of a walled face has
/// a mirror image behind it (Libersky et al. 1993), with the parent's mass, density, smoothing
/// length and sound speed, its position and velocity reflected in the face, and its pressure
/// extended hydrostatically, p_g = p + rho g . (x_g - x). Near a corner the particle also has
/// the image in both faces. The images make the flow next to the wall that of the symmetric
/// problem: the continuity and pressure sums see a complete kernel, and the normal velocity
/// vanishes on the face. The image of particle j moves with j, so the images chosen at a list
/// rebuild serve until the next one (the parent must come within `radius` to interact).
template <int D>
struct Ghosts {
  // Per image: parent index, reflection (-1 on the mirrored axes) and offset (twice the face
  // coordinate there); and the image's state.
  std::vector<Index> parent;
  std::vector<Vec<D>> sign, offset, x, v;
  std::vector<Real> p;

  bool empty() const { return parent.empty(); }
  Index size() const { return static_cast<Index>(parent.size()); }

  /// The images of the particles at xp (in index order) within `radius` of a face in `walls` of
  /// the box [lo, hi]; the state vectors are sized to match.
  void select(std::span<const Vec<D>> xp, Real radius, const std::vector<parts::Face>& walls,
              const Vec<D>& lo, const Vec<D>& hi);

  /// The images' positions for parent positions xp.
  void place(std::span<const Vec<D>> xp) {
    parallel::for_each(size(), [&](Index g) {
      x[at(g)] = offset[at(g)] + sign[at(g)].cwiseProduct(xp[at(parent[at(g)])]);
    });
  }
};

}  // namespace crater::sph
