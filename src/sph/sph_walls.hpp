// The walls of an SPH part (sph_part.cpp): dummy wall particles behind no-slip walls (Adami, Hu
// & Adams 2012) and mirror images behind free-slip walls (Libersky et al. 1993), as laid out
// from the domain box; their states are set from the fluid's at each force stage
// (SphPart::wall_state, SphPart::ghost_state).
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "core/index.hpp"
#include "core/types.hpp"
#include "neighbors/neighbor_list.hpp"
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

/// The fluid particles' arrays the wall state is averaged from.
/// Puts a particle at x that crossed walled faces of the box [lo, hi] back by specular
/// reflection (its normal velocity vh and acceleration a reversed): at a free-slip wall this is
/// the symmetry condition itself (the particle and its image trade places); at a no-slip wall a
/// safeguard behind the dummy particles' pressure. Conserves kinetic energy; the wall takes
/// the momentum. Returns the faces crossed and the deepest crossing (a particle sliding on a
/// free-slip floor at a free surface, where the pressure is about zero, can dip below it by
/// round-off: the image's push vanishes as the kernel gradient does at r = 0).
struct Reflection {
  int faces = 0;     // faces crossed
  Real deepest = 0;  // the deepest crossing [m]
};
template <int D>
Reflection reflect_at_walls(const std::vector<parts::Face>& walls, const Vec<D>& lo,
                            const Vec<D>& hi, Vec<D>& x, Vec<D>& vh, Vec<D>& a) {
  Reflection r;
  for (const parts::Face f : walls) {
    const int axis = static_cast<int>(f) / 2;
    const bool low = static_cast<int>(f) % 2 == 0;
    const Real face = low ? lo[axis] : hi[axis];
    const Real depth = low ? face - x[axis] : x[axis] - face;
    if (depth > 0) {
      x[axis] = low ? face + depth : face - depth;
      vh[axis] = -vh[axis];
      a[axis] = -a[axis];
      ++r.faces;
      r.deepest = std::max(r.deepest, depth);
    }
  }
  return r;
}

template <int D>
struct FluidArrays {
  const std::vector<Vec<D>>& x;
  const std::vector<Real>&h, &p, &rho, &c;
  const std::vector<Vec<D>>& v;
};

/// Per dummy wall particle: pressure, density, sound speed, and the velocity the viscous terms
/// see.
template <int D>
struct WallState {
  std::vector<Real> p, rho, c;
  std::vector<Vec<D>> v;
};

/// Adami et al. (2012) eqs. 27-28: a wall particle's pressure is the kernel-weighted average of
/// its fluid neighbours' plus the hydrostatic part, p_w = (sum_f p_f W_wf + g . sum_f rho_f
/// r_wf W_wf) / sum_f W_wf (fixed walls: no wall acceleration); density and sound speed are
/// the same averages (Shepard); the velocity for the viscous terms is the averaged fluid
/// velocity mirrored in the wall (eq. 22 for no slip). W at hbar = (h0 + h_f)/2; each wall
/// particle sums over its list (to_fluid) in order.
/// `only` (if not empty): the wall particles to average (1), the others keep their state (on
/// ranks: those whose fluid neighbours are not all on this rank, SphPart::wall_complete_).
template <class Kernel, int D>
void average_wall_state(const std::vector<Vec<D>>& wall_x, const std::vector<Vec<D>>& mirror,
                        const neighbors::NeighborList& to_fluid, const FluidArrays<D>& f, Real h0,
                        const Vec<D>& g, bool no_slip, const std::vector<std::uint8_t>& only,
                        WallState<D>& out) {
  parallel::for_each(static_cast<Index>(wall_x.size()), [&](Index w) {
    const auto k = at(w);
    if (!only.empty() && !only[k]) return;
    Real sw = 0, sp = 0, srho = 0, sc = 0;
    Vec<D> sv = Vec<D>::Zero(), srw = Vec<D>::Zero();
    for (const Index j : to_fluid.of(w)) {
      const auto fj = at(j);
      const Vec<D> rwf = wall_x[k] - f.x[fj];
      const Real hbar = 0.5 * (h0 + f.h[fj]);
      const Real wgt = Kernel::w(rwf.norm(), hbar);
      sw += wgt;
      sp += f.p[fj] * wgt;
      srho += f.rho[fj] * wgt;
      sc += f.c[fj] * wgt;
      sv += f.v[fj] * wgt;
      srw += f.rho[fj] * rwf * wgt;
    }
    if (sw > 0) {
      out.p[k] = (sp + g.dot(srw)) / sw;
      out.rho[k] = srho / sw;
      out.c[k] = sc / sw;
      // The velocity the viscous terms see: the fluid's, mirrored in the wall (no slip: all
      // of it, 2 v_wall - v; free slip: only its normal part, so sliding costs nothing).
      const Vec<D> vf = sv / sw;
      out.v[k] = no_slip ? Vec<D>(-vf) : Vec<D>(vf.cwiseProduct(mirror[k]));
    } else {
      out.p[k] = 0;
      out.c[k] = 0;
      out.v[k] = Vec<D>::Zero();
    }
  });
}

}  // namespace crater::sph
