// Wall particles and mirror images of an SPH part; see sph_walls.hpp.
#include "sph/sph_walls.hpp"

#include <array>
#include <cmath>

#include "parts/region.hpp"

namespace crater::sph {

using parts::to_vec;

template <int D>
WallLattice<D> wall_lattice(const parts::Domain& domain, const std::vector<parts::Face>& faces,
                            int layers, Real s) {
  const Vec<D> lo = to_vec<D>(domain.min_m), hi = to_vec<D>(domain.max_m);
  auto walled = [&](int axis, int side) {
    for (auto f : faces)
      if (static_cast<int>(f) == 2 * axis + side) return true;
    return false;
  };
  // Coordinates along an axis: inside [lo, hi] at lo + (i + 1/2) s; beyond a face at
  // face -/+ (k + 1/2) s.
  auto coords = [&](int axis, bool extend) {
    std::vector<Real> v;
    const auto n = static_cast<Index>(std::llround((hi[axis] - lo[axis]) / s));
    if (extend && walled(axis, 0))
      for (int k = layers - 1; k >= 0; --k)
        v.push_back(lo[axis] - (k + 0.5) * s);
    for (Index i = 0; i < n; ++i)
      v.push_back(lo[axis] + (static_cast<Real>(i) + 0.5) * s);
    if (extend && walled(axis, 1))
      for (int k = 0; k < layers; ++k)
        v.push_back(hi[axis] + (k + 0.5) * s);
    return v;
  };
  WallLattice<D> out;
  for (int a = 0; a < D; ++a)
    for (int side = 0; side < 2; ++side) {
      if (!walled(a, side)) continue;
      std::vector<std::vector<Real>> axes(D);
      for (int d = 0; d < D; ++d) {
        if (d == a) {
          for (int k = 0; k < layers; ++k)
            axes[d].push_back(side == 0 ? lo[a] - (k + 0.5) * s : hi[a] + (k + 0.5) * s);
        } else {
          axes[d] = coords(d, d > a);
        }
      }
      std::vector<std::size_t> i(D, 0);
      while (true) {
        Vec<D> x;
        Vec<D> mirror;
        for (int d = 0; d < D; ++d) {
          x[d] = axes[d][i[d]];
          mirror[d] = (x[d] < lo[d] || x[d] > hi[d]) ? -1.0 : 1.0;
        }
        out.x.push_back(x);
        out.mirror.push_back(mirror);
        int d = 0;
        while (d < D && ++i[d] == axes[d].size())
          i[d++] = 0;
        if (d == D) break;
      }
    }
  return out;
}

template <int D>
void Ghosts<D>::select(std::span<const Vec<D>> xp, Real radius,
                       const std::vector<parts::Face>& walls, const Vec<D>& lo, const Vec<D>& hi) {
  parent.clear();
  sign.clear();
  offset.clear();
  const auto n = static_cast<Index>(xp.size());
  for (Index j = 0; j < n; ++j) {
    // Per axis: no reflection (0), in the low face (1) or in the high face (2), if walled and
    // within reach.
    std::array<std::array<int, 3>, D> options{};
    std::array<int, D> count{};
    for (int a = 0; a < D; ++a) {
      options[a][count[a]++] = 0;
      for (const parts::Face f : walls) {
        if (static_cast<int>(f) / 2 != a) continue;
        const bool low = static_cast<int>(f) % 2 == 0;
        const Vec<D>& xj = xp[static_cast<std::size_t>(j)];
        const Real d = low ? xj[a] - lo[a] : hi[a] - xj[a];
        if (d < radius) options[a][count[a]++] = low ? 1 : 2;
      }
    }
    std::array<int, D> k{};
    while (true) {
      bool any = false;
      Vec<D> reflect = Vec<D>::Ones(), shift = Vec<D>::Zero();
      for (int a = 0; a < D; ++a) {
        const int o = options[a][k[a]];
        if (o == 0) continue;
        any = true;
        reflect[a] = -1;
        shift[a] = 2 * (o == 1 ? lo[a] : hi[a]);
      }
      if (any) {
        parent.push_back(j);
        sign.push_back(reflect);
        offset.push_back(shift);
      }
      int a = 0;
      while (a < D && ++k[a] == count[a])
        k[a++] = 0;
      if (a == D) break;
    }
  }
  x.resize(parent.size());
  v.resize(parent.size());
  p.resize(parent.size());
}

template WallLattice<2> wall_lattice<2>(const parts::Domain&, const std::vector<parts::Face>&, int,
                                        Real);
template WallLattice<3> wall_lattice<3>(const parts::Domain&, const std::vector<parts::Face>&, int,
                                        Real);
template struct Ghosts<2>;
template struct Ghosts<3>;

}  // namespace crater::sph
