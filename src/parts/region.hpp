// Regions of space that parts are filled over (box, disk, sphere), and their geometry: shared
// by the methods that lay entities in them and by the scenario reader that describes them.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"

namespace crater::parts {

/// A point or vector as the scenario gives it: 3 entries, the first `dimension` meaningful.
using Vec3 = std::array<Real, 3>;

enum class RegionType { Box, Disk, Sphere };

struct RegionConfig {
  RegionType type = RegionType::Box;
  Vec3 min_m{}, max_m{};  // box
  Vec3 center_m{};        // disk, sphere
  Real radius_m = 0;
  SourceLocation where;
};

/// The first D entries of a config vector.
template <int D>
Vec<D> to_vec(const Vec3& a) {
  Vec<D> v;
  for (int d = 0; d < D; ++d)
    v[d] = a[static_cast<std::size_t>(d)];
  return v;
}

/// Whether x lies in the region (boundary included).
template <int D>
bool region_contains(const RegionConfig& r, const Vec<D>& x) {
  if (r.type == RegionType::Box) {
    for (int d = 0; d < D; ++d)
      if (x[d] < r.min_m[static_cast<std::size_t>(d)] ||
          x[d] > r.max_m[static_cast<std::size_t>(d)])
        return false;
    return true;
  }
  return (x - to_vec<D>(r.center_m)).norm() <= r.radius_m;
}

/// Distance from x to the region (0 inside) [m].
template <int D>
Real region_distance(const RegionConfig& r, const Vec<D>& x) {
  if (r.type == RegionType::Box) {
    Real s = 0;
    for (int d = 0; d < D; ++d) {
      const Real e = std::max({r.min_m[static_cast<std::size_t>(d)] - x[d], Real(0),
                               x[d] - r.max_m[static_cast<std::size_t>(d)]});
      s += e * e;
    }
    return std::sqrt(s);
  }
  return std::max(Real(0), (x - to_vec<D>(r.center_m)).norm() - r.radius_m);
}

/// Whether a particle of radius `radius` at x reaches into one of the `carving` regions: such
/// particles are not laid.
template <int D>
bool carved(const std::vector<RegionConfig>& carving, const Vec<D>& x, Real radius) {
  for (const RegionConfig& r : carving)
    if (region_distance<D>(r, x) < radius) return true;
  return false;
}

/// A plane of symmetry a lattice is cut at: x[axis] = plane, the model on the side below it
/// (upper: the plane is the domain's upper face) or above it.
struct LatticeCut {
  int axis = 0;
  Real plane = 0;
  bool upper = false;
};

/// Centres of a square/cubic lattice of pitch s over the region's bounding box, centred in
/// it, kept when inside the region. Each point stands for a cell of volume s^D. Where the box
/// reaches across one of the `cuts` (planes of symmetry), the lattice is laid from the plane,
/// half a pitch off it (so the mirror images continue it), on the model's side only.
template <int D>
std::vector<Vec<D>> region_lattice(const RegionConfig& r, Real s,
                                   const std::vector<LatticeCut>& cuts = {}) {
  Vec<D> lo, hi;
  for (int d = 0; d < D; ++d) {
    const auto k = static_cast<std::size_t>(d);
    lo[d] = r.type == RegionType::Box ? r.min_m[k] : r.center_m[k] - r.radius_m;
    hi[d] = r.type == RegionType::Box ? r.max_m[k] : r.center_m[k] + r.radius_m;
  }
  IVec<D> n;
  for (int d = 0; d < D; ++d)
    n[d] = std::max<std::int64_t>(
        1, static_cast<std::int64_t>(std::floor((hi[d] - lo[d]) / s + 1e-9)));
  Vec<D> start;
  for (int d = 0; d < D; ++d)
    start[d] = lo[d] + 0.5 * ((hi[d] - lo[d]) - static_cast<Real>(n[d] - 1) * s);
  for (const LatticeCut& cut : cuts) {
    const int d = cut.axis;
    const Real plane = cut.plane;
    const bool upper = cut.upper;
    if (d >= D || !(lo[d] < plane && plane < hi[d])) continue;
    const Real from = upper ? lo[d] : plane, to = upper ? plane : hi[d];
    const auto count = static_cast<std::int64_t>(std::floor((to - from) / s + 1e-9));
    if (count < 1) return {};
    n[d] = count;
    // Points at plane -/+ (k + 1/2) s; from the lower side, the one nearest the far end first.
    start[d] = upper ? plane - (static_cast<Real>(count) - 0.5) * s : plane + 0.5 * s;
  }
  std::vector<Vec<D>> pts;
  IVec<D> i = IVec<D>::Zero();
  while (true) {
    Vec<D> x;
    for (int d = 0; d < D; ++d)
      x[d] = start[d] + static_cast<Real>(i[d]) * s;
    if (region_contains<D>(r, x)) pts.push_back(x);
    int d = 0;
    while (d < D && ++i[d] == n[d])
      i[d++] = 0;
    if (d == D) break;
  }
  return pts;
}

/// Volume of a box, disk or sphere region (area in 2D).
template <int D>
Real region_volume_of(const RegionConfig& r) {
  if (r.type == RegionType::Box) {
    Real v = 1;
    for (int d = 0; d < D; ++d)
      v *= std::max(Real(0),
                    r.max_m[static_cast<std::size_t>(d)] - r.min_m[static_cast<std::size_t>(d)]);
    return v;
  }
  const Real a = r.radius_m;
  return D == 2 ? std::numbers::pi * a * a : 4.0 / 3.0 * std::numbers::pi * a * a * a;
}

/// The part of box region `box` that the `carving` regions take [m^D], the carving regions
/// assumed apart from each other: exact for boxes, and for disks and spheres wholly inside the
/// box; otherwise by counting the points of a lattice over the region's bounding square (512^2)
/// or cube (128^3) that lie in both (relative error about 1e-3).
template <int D>
Real carved_volume(const RegionConfig& box, const std::vector<RegionConfig>& carving) {
  Real carved = 0;
  for (const RegionConfig& k : carving) {
    if (k.type == RegionType::Box) {
      Real v = 1;
      for (int d = 0; d < D; ++d) {
        const auto i = static_cast<std::size_t>(d);
        v *= std::max(Real(0),
                      std::min(box.max_m[i], k.max_m[i]) - std::max(box.min_m[i], k.min_m[i]));
      }
      carved += v;
      continue;
    }
    bool inside = true;
    for (int d = 0; d < D; ++d) {
      const auto i = static_cast<std::size_t>(d);
      inside &=
          k.center_m[i] - k.radius_m >= box.min_m[i] && k.center_m[i] + k.radius_m <= box.max_m[i];
    }
    if (inside) {
      carved += region_volume_of<D>(k);
      continue;
    }
    constexpr int kN = D == 2 ? 512 : 128;
    const Real h = 2 * k.radius_m / kN;
    std::int64_t count = 0, total = 1;
    for (int d = 0; d < D; ++d)
      total *= kN;
    for (std::int64_t q = 0; q < total; ++q) {
      Vec<D> x;
      std::int64_t rest = q;
      for (int d = 0; d < D; ++d) {
        x[d] = k.center_m[static_cast<std::size_t>(d)] - k.radius_m +
               (static_cast<Real>(rest % kN) + Real(0.5)) * h;
        rest /= kN;
      }
      if (region_contains<D>(k, x) && region_contains<D>(box, x)) ++count;
    }
    carved += static_cast<Real>(count) * std::pow(h, D);
  }
  return carved;
}

}  // namespace crater::parts
