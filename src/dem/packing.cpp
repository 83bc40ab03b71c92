#include "dem/packing.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iterator>
#include <numbers>
#include <random>
#include <sstream>
#include <unordered_map>

#include "core/error.hpp"

namespace crater::dem {

template <int D>
Real grain_volume(Real r) {
  if constexpr (D == 2)
    return std::numbers::pi * r * r;
  else
    return 4.0 / 3.0 * std::numbers::pi * r * r * r;
}

template <int D>
Real region_volume(const parts::RegionConfig& region) {
  if (region.type == parts::RegionType::Box) {
    Real v = 1;
    for (int d = 0; d < D; ++d) {
      const auto k = static_cast<std::size_t>(d);
      v *= region.max_m[k] - region.min_m[k];
    }
    return v;
  }
  return grain_volume<D>(region.radius_m);
}

template <int D>
std::vector<Real> draw_radii(const PackingSettings& packing, Real r_min, Real r_max,
                             Real solid_volume, std::uint64_t seed, std::size_t max_grains,
                             const SourceLocation& where, const std::string& key) {
  std::mt19937_64 rng(seed);
  std::vector<Real> radii;
  auto too_many = [&] {
    throw InputError(where, key,
                     fmt::format("a packing of more than {} grains (the region is too large "
                                 "for the grain size); enlarge the grains or shrink the region",
                                 max_grains));
  };
  // Grains of radius in [a, b] until their volume reaches `target` (the last grain is kept if
  // it brings the total nearer the target than without it).
  auto fill = [&](Real a, Real b, Real target) {
    std::uniform_real_distribution<Real> draw(a, b);
    Real got = 0;
    while (true) {
      const Real r = a == b ? a : draw(rng);
      const Real v = grain_volume<D>(r);
      if (got + 0.5 * v > target) break;
      radii.push_back(r);
      got += v;
      if (radii.size() > max_grains) too_many();
    }
  };
  const auto& d = packing.sieve_diameter_m;
  const auto& f = packing.sieve_passing;
  if (d.empty()) {
    fill(r_min, r_max, solid_volume);
  } else {
    // Mass (= solid volume, one density) fraction f_k - f_{k-1} in diameters [d_{k-1}, d_k];
    // what passes the finest sieve is taken at its size.
    fill(0.5 * d[0], 0.5 * d[0], f[0] * solid_volume);
    for (std::size_t k = 1; k < d.size(); ++k)
      fill(0.5 * d[k - 1], 0.5 * d[k], (f[k] - f[k - 1]) * solid_volume);
  }
  if (radii.empty())
    throw InputError(where, key,
                     fmt::format("no grain to place: the region's solid volume ({:.4g} m^{}) "
                                 "is less than half a grain of the sizes asked for (radius "
                                 "up to {:.4g} m); enlarge the region or shrink the grains",
                                 solid_volume, D, d.empty() ? r_max : 0.5 * d.back()));
  return radii;
}

namespace {

template <int D>
struct HashGrid {
  Real cell;
  Vec<D> origin;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells;

  std::array<std::int64_t, 3> index(const Vec<D>& x) const {
    std::array<std::int64_t, 3> c{0, 0, 0};
    for (int d = 0; d < D; ++d)
      c[static_cast<std::size_t>(d)] =
          static_cast<std::int64_t>(std::floor((x[d] - origin[d]) / cell));
    return c;
  }
  static std::uint64_t key(const std::array<std::int64_t, 3>& c) {
    const auto u = [](std::int64_t v) { return static_cast<std::uint64_t>(v + (1 << 20)); };
    return (u(c[0]) << 42) | (u(c[1]) << 21) | u(c[2]);
  }
};

}  // namespace

template <int D>
std::vector<Grain<D>> random_packing(const parts::RegionConfig& region, std::vector<Real> radii,
                                     const Vec<D>& gravity, const Vec<D>& domain_lo,
                                     const Vec<D>& domain_hi, std::uint64_t seed,
                                     const SourceLocation& where, const std::string& key) {
  std::sort(radii.begin(), radii.end(), std::greater<>());
  const bool box = region.type == parts::RegionType::Box;
  Vec<D> lo, hi, center;
  for (int d = 0; d < D; ++d) {
    const auto k = static_cast<std::size_t>(d);
    center[d] = region.center_m[k];
    lo[d] = box ? region.min_m[k] : region.center_m[k] - region.radius_m;
    hi[d] = box ? region.max_m[k] : region.center_m[k] + region.radius_m;
  }
  // The column grows against gravity, in steps of a quarter of the region's height, up to the
  // domain's face.
  int up = 0;
  for (int d = 1; d < D; ++d)
    if (std::abs(gravity[d]) > std::abs(gravity[up])) up = d;
  const bool can_grow = box && gravity[up] != 0;
  const bool grow_high = gravity[up] < 0;
  const Real step = 0.25 * (hi[up] - lo[up]);
  const Real limit = grow_high ? domain_hi[up] : domain_lo[up];

  std::vector<Grain<D>> out;
  out.reserve(radii.size());
  if (radii.empty()) return out;
  HashGrid<D> grid{2 * radii.front(), lo, {}};
  std::mt19937_64 rng(seed ^ 0x9e3779b97f4a7c15ULL);
  std::uniform_real_distribution<Real> unit(0.0, 1.0);
  constexpr int kAttempts = 2000;

  auto fits = [&](const Vec<D>& x, Real r) {
    if (!box && (x - center).norm() > region.radius_m - r) return false;
    auto c = grid.index(x);
    std::array<std::int64_t, 3> n = c;
    const int zr = D == 3 ? 1 : 0;
    for (n[0] = c[0] - 1; n[0] <= c[0] + 1; ++n[0])
      for (n[1] = c[1] - 1; n[1] <= c[1] + 1; ++n[1])
        for (n[2] = c[2] - zr; n[2] <= c[2] + zr; ++n[2]) {
          const auto it = grid.cells.find(HashGrid<D>::key(n));
          if (it == grid.cells.end()) continue;
          for (const std::uint32_t j : it->second) {
            const Real s = r + out[j].r;
            if ((out[j].x - x).squaredNorm() < s * s) return false;
          }
        }
    return true;
  };

  for (const Real r : radii) {
    bool placed = false;
    while (!placed) {
      for (int attempt = 0; attempt < kAttempts && !placed; ++attempt) {
        Vec<D> x;
        for (int d = 0; d < D; ++d)
          x[d] = lo[d] + r + unit(rng) * std::max(0.0, hi[d] - lo[d] - 2 * r);
        if (fits(x, r)) {
          grid.cells[HashGrid<D>::key(grid.index(x))].push_back(
              static_cast<std::uint32_t>(out.size()));
          out.push_back({x, r});
          placed = true;
        }
      }
      if (placed) break;
      const bool at_limit = grow_high ? hi[up] >= limit : lo[up] <= limit;
      if (!can_grow || at_limit)
        throw InputError(
            where, key,
            fmt::format("could not place grain {} of {} (r = {:.4g} m) without overlap: the "
                        "random packing needs a looser start than the {} allows; raise the "
                        "porosity, or (box regions under gravity) the domain's face above the "
                        "region, so the column can grow",
                        out.size() + 1, radii.size(), r, can_grow ? "domain" : "region"));
      const Real before = grow_high ? hi[up] : lo[up];
      if (grow_high)
        hi[up] = std::min(limit, hi[up] + step);
      else
        lo[up] = std::max(limit, lo[up] - step);
      // A region tiny against its coordinates cannot grow in floating point (fuzzing found a
      // 256 m region at 1e18 m: the step rounded away and the loop never ended).
      if ((grow_high ? hi[up] : lo[up]) == before)
        throw InputError(where, key,
                         fmt::format("a region whose height ({:.3g} m) the column can grow by in "
                                     "floating point; at coordinates of {:.3g} m it cannot",
                                     step * 4, before));
    }
  }
  return out;
}

#define CRATER_PACKING(D)                                                                         \
  template Real grain_volume<D>(Real);                                                            \
  template Real region_volume<D>(const parts::RegionConfig&);                                     \
  template std::vector<Real> draw_radii<D>(const PackingSettings&, Real, Real, Real,              \
                                           std::uint64_t, std::size_t, const SourceLocation&,     \
                                           const std::string&);                                   \
  template std::vector<Grain<D>> random_packing<D>(                                               \
      const parts::RegionConfig&, std::vector<Real>, const Vec<D>&, const Vec<D>&, const Vec<D>&, \
      std::uint64_t, const SourceLocation&, const std::string&);
CRATER_PACKING(2)
CRATER_PACKING(3)
#undef CRATER_PACKING

}  // namespace crater::dem
